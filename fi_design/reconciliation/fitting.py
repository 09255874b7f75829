"""Fitting a candidate effect: bounded least squares, widened bounds, joint refinement.

Every candidate is fitted by bounded least squares (scipy ``least_squares``,
trust-region reflective) on coordinates scaled to [0, 1], from the two best
of its starting points. Each start is first fitted on the move samples alone
with a robust loss (soft L1; the moves keep the objective smooth where slips
in the settle and hold segments make it rugged), then on everything.

A fit that ends on a search bound has not found a value: the bound is
widened (by :data:`~.spaces.WIDEN_LOG` on a log scale, by
:data:`~.spaces.WIDEN_LINEAR` times the span on a linear one) and the fit
continues from there, at most :data:`MAX_WIDEN` times; a parameter still on a
bound, or on a physical limit, is reported as such and the candidate cannot
be named.

The initial command the replay starts from is a nuisance coordinate of every
fit (:attr:`~.comparison.Comparison.command_width`): fitted with the effect,
reported apart from it, and its correlation with the effect's parameters
carried into their uncertainty.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from .. import spec as _spec
from .comparison import Comparison, ModelRun
from .spaces import Coord, Space

#: How many times a search bound is widened when the fit ends on it.
MAX_WIDEN = 2
#: A coordinate within this distance of 0 or 1 (in u) sits on its bound.
AT_BOUND = 1e-3


@dataclass(frozen=True, eq=False)
class FitOutcome:
    """A candidate's best fit.

    Attributes
    ----------
    space : Space
        The space as finally searched (bounds widened where the fit asked).
    u : ndarray, shape (k,)
        Best coordinates in [0, 1] (the effect's, then the nuisance's when
        there is one).
    values : dict of str to float
        The effect's parameters there, SI.
    residual : ndarray, shape (n,)
        Weighted residual there [noise units].
    chi2 : float
        Its squared norm [-].
    covariance : ndarray, shape (k, k), or None
        (J^T J)^+ of the effect's own coordinates, marginal over the
        nuisance (and over effects refitted with it), unscaled; None for an
        effect read from the data or a failed fit.
    jacobian : ndarray, shape (n, m), or None
        d(residual)/du at the optimum over every fitted coordinate.
    columns : slice
        The effect's own columns of ``jacobian``.
    run : ModelRun
        The simulation at the best point.
    entries : list
        The model's effect entries at the best point (the base and the effect).
    command : float
        The fitted initial-command correction [N] (0 without the nuisance).
    widened : int
        Bounds widened.
    at_bound : tuple of str
        Parameters on a search bound or physical limit at the end.
    n_simulations : int
        Simulations used.
    n_failed : int
        Of those, the ones that failed or ran away (an unstable loop).
    note : str
        What happened (a failed local fit, a bound).
    """

    space: Space
    u: np.ndarray
    values: dict
    residual: np.ndarray
    chi2: float
    covariance: np.ndarray | None
    jacobian: np.ndarray | None
    columns: slice
    run: ModelRun
    entries: list
    command: float
    widened: int
    at_bound: tuple
    n_simulations: int
    n_failed: int = 0
    note: str = ""


class Evaluation(NamedTuple):
    """The weighted residual of one run and the run itself."""

    residual: np.ndarray
    run: ModelRun


class Evaluations:
    """The evaluations of one fit by coordinates: every residual, the run of the best only.

    A fit evaluates tens to hundreds of points; a run holds every record
    sample of every channel, so keeping all of them made a reconciliation
    take about 20 kB per record sample (17 GB for two million samples). The
    residual (a few thousand entries at most) is kept for every point, the
    run only for the point with the smallest misfit so far, where a fit
    ends; a run asked for elsewhere is simulated again (the same inputs give
    the same run).
    """

    def __init__(self) -> None:
        self.residuals: dict[tuple, np.ndarray] = {}
        self.best: tuple | None = None  # (key, chi2, run)

    def residual(self, key: tuple) -> np.ndarray | None:
        """The residual at ``key``, None when not evaluated."""
        return self.residuals.get(key)

    def run(self, key: tuple) -> ModelRun | None:
        """The run at ``key`` when it is the best so far, else None."""
        return self.best[2] if self.best is not None and self.best[0] == key else None

    def add(self, key: tuple, residual: np.ndarray, run: ModelRun) -> None:
        """Keep the residual; keep the run while it is the best."""
        self.residuals[key] = residual
        chi2 = float(residual @ residual)
        if self.best is None or chi2 < self.best[1]:
            self.best = (key, chi2, run)


def effect_entry(name: str, values: dict):
    """A spec effect entry from SI values inside the catalogue bounds (no re-validation)."""
    return _spec.EFFECT_MODELS[name].model_construct(type=name, **values)


@dataclass(frozen=True, eq=False)
class Baseline:
    """The model a search starts from.

    Attributes
    ----------
    entries : list
        Its effect entries.
    run : ModelRun
        Its simulation.
    residual : ndarray
        Its weighted residual.
    chi2 : float
        Squared norm of the residual [-].
    command : float
        Its fitted initial-command correction [N].
    """

    entries: list
    run: ModelRun
    residual: np.ndarray
    chi2: float
    command: float = 0.0


def fit_baseline(cmp: Comparison, entries: list, start: float = 0.0) -> Baseline:
    """The model with effect entries, its initial-command nuisance fitted alone."""
    coord = command_coord(cmp)
    if coord is None:
        run = cmp.run(entries)
        r = cmp.residuals(run)
        return Baseline(entries, run, r, float(r @ r), 0.0)
    from scipy.optimize import minimize_scalar

    runs: dict[float, Evaluation] = {}

    def chi2(a: float) -> float:
        run = cmp.run(entries, command_correction=float(a))
        r = cmp.residuals(run)
        runs[float(a)] = Evaluation(r, run)
        return float(r @ r)

    chi2(start)
    minimize_scalar(chi2, bounds=(coord.lo, coord.hi), method="bounded",
                    options={"xatol": (coord.hi - coord.lo) / 200.0, "maxiter": 12})
    best = min(runs, key=lambda a: float(runs[a].residual @ runs[a].residual))
    ev = runs[best]
    return Baseline(entries, ev.run, ev.residual, float(ev.residual @ ev.residual), best)


def command_coord(cmp: Comparison) -> Coord | None:
    """The initial-command nuisance coordinate (a correction in N), or None without one."""
    w = cmp.command_width
    return Coord("initial_command", -w, w) if w > 0 else None


class Objective:
    """Residuals of one candidate as a function of u, with a cache.

    ``u`` holds the effect's coordinates, then the initial-command nuisance
    when the comparison has one.

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    space : Space
        The candidate.
    base : list
        Effect entries of the model the candidate is added to (an entry of
        the same type is replaced).
    """

    def __init__(self, cmp: Comparison, space: Space, base: list) -> None:
        self.cmp = cmp
        self.space = space
        self.base = [e for e in base if e.type != space.name]
        self.nuisance = command_coord(cmp)
        self.coords = list(space.coords) + ([self.nuisance] if self.nuisance else [])
        self.k = len(space.coords)
        self.cache = Evaluations()
        self.n_sims = 0
        self.n_failed = 0

    def values(self, u: np.ndarray) -> dict:
        """The effect's parameters at u, SI."""
        if self.space.method == "fixed":
            return dict(self.space.fixed)
        v = {c.name: c.value(float(x)) for c, x in zip(self.space.coords, u[:self.k])}
        return self.space.build(v)

    def command(self, u: np.ndarray) -> float:
        """The initial-command correction at u [N]."""
        return self.nuisance.value(float(u[self.k])) if self.nuisance else 0.0

    def value_jacobian(self, u: np.ndarray) -> np.ndarray:
        """d(parameter)/du of the effect's coordinates (central differences, phases unwrapped).

        Rows follow the order of :meth:`values`, columns the effect's coordinates.
        """
        names = list(self.values(u))
        G = np.zeros((len(names), self.k))
        for j in range(self.k):
            up, dn = np.array(u, float), np.array(u, float)
            up[j] = min(up[j] + 1e-6, 1.0)
            dn[j] = max(dn[j] - 1e-6, 0.0)
            a, b = self.values(up), self.values(dn)
            for i, k in enumerate(names):
                d = a[k] - b[k]
                if k == "phase":
                    d = (d + math.pi) % (2 * math.pi) - math.pi
                G[i, j] = d / (up[j] - dn[j])
        return G

    def entries(self, u: np.ndarray) -> list:
        """The model's effect entries at u."""
        return self.base + [effect_entry(self.space.name, self.values(u))]

    def evaluate(self, u: np.ndarray) -> Evaluation:
        """Residual and run at u (cached; see :class:`Evaluations`)."""
        key = tuple(np.round(np.asarray(u, float), 12))
        residual, run = self.cache.residual(key), self.cache.run(key)
        if residual is None or run is None:
            self.n_sims += 1
            run = self.cmp.run(self.entries(u), quantize=self.space.quantize,
                               command_correction=self.command(u))
            self.n_failed += int(not run.ok)
            if residual is None:
                residual = self.cmp.residuals(run)
                self.cache.add(key, residual, run)
        return Evaluation(residual, run)

    def __call__(self, u: np.ndarray) -> np.ndarray:
        key = tuple(np.round(np.asarray(u, float), 12))
        residual = self.cache.residual(key)
        return residual if residual is not None else self.evaluate(u).residual

    def jac(self, u: np.ndarray) -> np.ndarray:
        """d(residual)/du by forward differences (backward at the upper bound)."""
        return _jacobian(self, self.coords, u)


def marginal_covariance(J: np.ndarray | None, cols: slice) -> np.ndarray | None:
    """(J^T J)^+ restricted to the coordinates ``cols``: marginal over all the others."""
    if J is None or J.shape[1] == 0 or cols.stop == cols.start:
        return None
    return np.linalg.pinv(J.T @ J)[cols, cols]


def _jacobian(f, coords, u: np.ndarray) -> np.ndarray:
    r0 = f(u)
    J = np.empty((len(r0), len(u)))
    for j, c in enumerate(coords):
        h = c.step
        up = np.array(u, float)
        if up[j] + h <= 1.0:
            up[j] += h
        else:
            up[j] -= h
            h = -h
        J[:, j] = (f(up) - r0) / h
    return J


def _with_command(ob: Objective, u_effect: np.ndarray, command: float) -> np.ndarray:
    """The full u of an objective: effect coordinates and the nuisance at ``command`` [N]."""
    if ob.nuisance is None:
        return np.asarray(u_effect, float)
    return np.append(np.asarray(u_effect, float), ob.nuisance.u_of(command))


def fit(cmp: Comparison, space: Space, base: list, command: float = 0.0) -> FitOutcome:
    """Fit one candidate, widening a bound the fit ends on (at most :data:`MAX_WIDEN` times).

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    space : Space
        The candidate.
    base : list
        Effect entries of the model the candidate is added to.
    command : float
        Initial-command correction of that model [N]: where the nuisance starts.
    """
    ob = Objective(cmp, space, base)
    if space.method == "fixed" and ob.nuisance is None:
        u = np.zeros(0)
        ev = ob.evaluate(u)
        return FitOutcome(space, u, ob.values(u), ev.residual, float(ev.residual @ ev.residual),
                          None, None, slice(0, 0), ev.run, ob.entries(u), 0.0, 0, (), ob.n_sims,
                          ob.n_failed, "read from the data")
    starts = [_with_command(ob, u, command) for u in space.starts] or \
        [_with_command(ob, np.zeros(0), command)]
    local = _local_fit(ob, starts)
    n_sims, n_failed = ob.n_sims, ob.n_failed
    widened = 0
    while widened < MAX_WIDEN and local.u is not None:
        coords = list(space.coords if widened == 0 else ob.space.coords)
        changed = False
        for j, (c, x) in enumerate(zip(coords, local.u[:ob.k])):
            side = _bound_side(c, x)
            if side is None:
                continue
            wide = c.widened(upper=side)
            if wide is not None:
                coords[j] = wide
                changed = True
        if not changed:
            break
        value = {c.name: c.value(float(x)) for c, x in zip(ob.space.coords, local.u[:ob.k])}
        cmd = ob.command(local.u)
        ob = Objective(cmp, replace(space, coords=coords), base)
        u0 = _with_command(ob, np.array([c.u_of(value[c.name]) for c in coords]), cmd)
        local = _local_fit(ob, [u0])
        n_sims += ob.n_sims
        n_failed += ob.n_failed
        widened += 1
    if local.u is None:
        u = local.fallback
        ev = ob.evaluate(u)
        return FitOutcome(ob.space, u, ob.values(u), ev.residual,
                          float(ev.residual @ ev.residual), None, None, slice(0, ob.k), ev.run,
                          ob.entries(u),
                          ob.command(u), widened, (), n_sims, n_failed,
                          "the local fit failed; the best starting point is reported")
    ev = ob.evaluate(local.u)
    at = _at_bound(ob.space, local.u[:ob.k])
    note = ""
    if at:
        note = ("on the search bound" + (f" after widening it {widened} time(s)" if widened else "")
                + ": " + ", ".join(at))
    return FitOutcome(ob.space, local.u, ob.values(local.u), ev.residual,
                      float(ev.residual @ ev.residual),
                      marginal_covariance(local.jacobian, slice(0, ob.k)), local.jacobian,
                      slice(0, ob.k), ev.run,
                      ob.entries(local.u), ob.command(local.u), widened, at, n_sims, n_failed,
                      note)


def _at_bound(space: Space, u: np.ndarray) -> tuple:
    """Parameters whose coordinate sits on a bound."""
    return tuple(name for c, x in zip(space.coords, u) for name in _parameter_names(space, c)
                 if _bound_side(c, x) is not None)


def _parameter_names(space: Space, c) -> list[str]:
    """The effect parameters a coordinate stands for (a mass scale stands for both masses)."""
    if c.name == "scale":
        return ["stage_mass", "cart_mass"]
    if c.name == "phase_center":
        return ["phase"]
    return [c.name]


def _bound_side(c, x: float) -> bool | None:
    """True on the upper bound, False on the lower, None inside (phases never)."""
    if c.periodic:
        return None
    if x > 1.0 - AT_BOUND:
        return True
    if x < AT_BOUND:
        return False
    return None


@dataclass(frozen=True, eq=False)
class _Local:
    u: np.ndarray | None
    jacobian: np.ndarray | None
    fallback: np.ndarray


def _local_fit(ob: Objective, starts: list) -> _Local:
    """Least squares from the two best starts (staged: moves with a robust loss, then all)."""
    from scipy.optimize import least_squares

    mask = ob.cmp.move_entries
    staged = mask is not None and 0 < mask.sum() < len(mask)

    def sub(u):
        return ob(u)[mask]

    def sub_jac(u):
        return ob.jac(u)[mask]

    def score(u):
        r = sub(u) if staged else ob(u)
        return float(r @ r)

    scored = sorted(((score(u), i, u) for i, u in enumerate(starts)), key=lambda s: s[0])
    chosen: list[np.ndarray] = []
    for _, _, u in scored:
        if all(np.max(np.abs(u - c)) > 0.05 for c in chosen):
            chosen.append(u)
        if len(chosen) >= 2:
            break
    best_c2, best_u, best_J = math.inf, None, None
    k = len(ob.coords)
    lo, hi = np.zeros(k), np.ones(k)
    for u0 in chosen:
        u0 = np.clip(u0, 1e-6, 1 - 1e-6)
        try:
            if staged:
                sol = least_squares(sub, u0, jac=sub_jac, bounds=(lo, hi), method="trf",
                                    loss="soft_l1", f_scale=3.0, x_scale=1.0, max_nfev=25,
                                    ftol=1e-6, xtol=1e-5, gtol=1e-8)
                u0 = np.clip(sol.x, 1e-6, 1 - 1e-6)
            sol = least_squares(ob, u0, jac=ob.jac, bounds=(lo, hi), method="trf",
                                x_scale=1.0, max_nfev=30, ftol=1e-6, xtol=1e-5, gtol=1e-8)
        except (ValueError, np.linalg.LinAlgError):
            continue
        c2 = float(sol.fun @ sol.fun)
        if c2 < best_c2:
            best_c2, best_u, best_J = c2, sol.x, sol.jac
    return _Local(best_u, best_J, scored[0][2] if scored else np.full(k, 0.5))


# --------------------------------------------------------------------------- joint refinement


class JointObjective:
    """Residuals of several effects fitted together (their u concatenated, then the nuisance).

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    spaces : list of Space
        The effects, each as finally searched.
    base : list
        Effect entries of the model before any of them.
    """

    def __init__(self, cmp: Comparison, spaces: list, base: list) -> None:
        self.cmp = cmp
        self.obs = [Objective(cmp, sp, []) for sp in spaces]
        names = {sp.name for sp in spaces}
        self.base = [e for e in base if e.type not in names]
        self.slices = []
        i = 0
        for sp in spaces:
            self.slices.append(slice(i, i + len(sp.coords)))
            i += len(sp.coords)
        self.nuisance = command_coord(cmp)
        self.coords = [c for sp in spaces for c in sp.coords] + \
            ([self.nuisance] if self.nuisance else [])
        self.cache = Evaluations()
        self.n_sims = 0

    def entries(self, u: np.ndarray) -> list:
        """The model's effect entries at u."""
        return self.base + [effect_entry(ob.space.name, ob.values(u[sl]))
                            for ob, sl in zip(self.obs, self.slices)]

    def command(self, u: np.ndarray) -> float:
        """The initial-command correction at u [N]."""
        return self.nuisance.value(float(u[-1])) if self.nuisance else 0.0

    def quantize(self) -> float | None:
        """The sensor lattice step when one of the effects is quantization."""
        return next((ob.space.quantize for ob in self.obs if ob.space.quantize), None)

    def evaluate(self, u: np.ndarray) -> Evaluation:
        """Residual and run at u (cached; see :class:`Evaluations`)."""
        key = tuple(np.round(np.asarray(u, float), 12))
        residual, run = self.cache.residual(key), self.cache.run(key)
        if residual is None or run is None:
            self.n_sims += 1
            run = self.cmp.run(self.entries(u), quantize=self.quantize(),
                               command_correction=self.command(u))
            if residual is None:
                residual = self.cmp.residuals(run)
                self.cache.add(key, residual, run)
        return Evaluation(residual, run)

    def __call__(self, u: np.ndarray) -> np.ndarray:
        key = tuple(np.round(np.asarray(u, float), 12))
        residual = self.cache.residual(key)
        return residual if residual is not None else self.evaluate(u).residual

    def jac(self, u: np.ndarray) -> np.ndarray:
        """d(residual)/du by forward differences."""
        return _jacobian(self, self.coords, u)


@dataclass(frozen=True, eq=False)
class JointFit:
    """The chosen effects refined together.

    Attributes
    ----------
    u : ndarray
        Best coordinates (concatenated).
    chi2 : float
        Weighted squared residual there [-].
    residual : ndarray
        Weighted residual there.
    jacobian : ndarray or None
        d(residual)/du there.
    """

    u: np.ndarray
    chi2: float
    residual: np.ndarray
    jacobian: np.ndarray | None


def joint_fit(jo: JointObjective, u0: np.ndarray) -> JointFit:
    """Refine several effects together from their one-by-one values."""
    from scipy.optimize import least_squares

    u0 = np.clip(u0, 1e-6, 1 - 1e-6)
    if len(u0) == 0:
        r = jo(u0)
        return JointFit(u0, float(r @ r), r, None)
    try:
        sol = least_squares(jo, u0, jac=jo.jac, bounds=(np.zeros(len(u0)), np.ones(len(u0))),
                            method="trf", max_nfev=60, ftol=1e-6, xtol=1e-6, gtol=1e-8)
    except (ValueError, np.linalg.LinAlgError):
        r = jo(u0)
        return JointFit(u0, float(r @ r), r, None)
    return JointFit(sol.x, float(sol.fun @ sol.fun), sol.fun, sol.jac)


def polish_jointly(cmp: Comparison, earlier: list, outcome: FitOutcome,
                   base: list) -> FitOutcome:
    """Refit a later candidate together with the effects named before it.

    An effect named first absorbs part of what a second one does; fitting
    the second alone on top of the first would then start from a biased
    model. The joint fit starts from both one-by-one values; the outcome
    keeps the candidate's own values and the marginal covariance of its
    coordinates (the earlier effects and the nuisance refitted with it).

    Parameters
    ----------
    cmp : Comparison
        The comparison.
    earlier : list of FitOutcome
        The effects named before, in order.
    outcome : FitOutcome
        The candidate fitted alone on top of them.
    base : list
        Effect entries of the model before any of them (the spec's).
    """
    spaces = [o.space for o in earlier] + [outcome.space]
    jo = JointObjective(cmp, spaces, base)
    k = len(outcome.space.coords)
    own = [outcome.u[:k]]
    if outcome.at_bound or not outcome.chi2 < earlier[-1].chi2:
        # alone it found nothing: the joint fit also starts from the middle of its range
        own.append(np.full(k, 0.5))
    jf = None
    for start in own:
        parts = [o.u[:len(o.space.coords)] for o in earlier] + [start]
        if jo.nuisance is not None:
            parts.append([jo.nuisance.u_of(earlier[-1].command)])
        trial = joint_fit(jo, np.concatenate(parts))
        if jf is None or trial.chi2 < jf.chi2:
            jf = trial
    if not jf.chi2 < outcome.chi2:
        return outcome
    ev = jo.evaluate(jf.u)
    sl = jo.slices[-1]
    ob = jo.obs[-1]
    u = jf.u[sl]
    at = _at_bound(outcome.space, u)
    note = "refitted with " + ", ".join(o.space.name for o in earlier)
    if at:
        note += "; on the search bound: " + ", ".join(at)
    return replace(outcome, u=np.concatenate([u, jf.u[len(jf.u) - (1 if jo.nuisance else 0):]]),
                   values=ob.values(u), residual=ev.residual, chi2=jf.chi2,
                   covariance=marginal_covariance(jf.jacobian, sl), jacobian=jf.jacobian,
                   columns=sl, run=ev.run,
                   entries=jo.entries(jf.u), command=jo.command(jf.u), at_bound=at,
                   n_simulations=outcome.n_simulations + jo.n_sims, note=note)
