"""Least-squares fits of LuGre's low-speed friction, with the sliding friction's errors carried.

Two models, both fitted with :func:`scipy.optimize.least_squares` on the
filtered full-rate signals (:class:`~.preprocess.Trace`) of a record:

**The presliding branch.** While the bearing does not slide, its position x
and the friction force F = u - m a - offset are tied by LuGre's bristle
equation: along a branch of monotonic motion in the direction s, with the
displacement w = s x and the bristle force Y = s sigma0 z,
``dY/dw = sigma0 (1 - Y / g(v))`` (:func:`bristle_force`, exact for g
constant over each sample interval). From Y_b at the branch's first sample
it rises as the straight line Y_b + sigma0 (w - w_b) of a stiff spring for
small displacements and bends over to the level g as the bristles saturate.
g is the Stribeck curve at the creep speed: Fs where the creep is slow
against the Stribeck velocity (the level fitted, kappa = 1 / Fs), or
``Fc + (Fs - Fc) exp(-(v / vs)^2)`` with vs known. The measured friction
adds bristle damping and viscous friction,
``y = s F - sigma2_s s v = Y + sigma1 s v (1 - Y / g)`` (LuGre's
sigma1 dz/dt, exactly). kappa, sigma0 and sigma1 are fitted, Y_b per branch;
sigma1 is a nuisance (left out, its effect, a lead of sigma1 / sigma0 in
time, would bias the level). Every variable carries noise: the residuals
are weighted by the effective variance
``s_y^2 + (dy/dw s_x)^2 + (dy/dv s_v)^2`` (errors in variables, consistent
where an unweighted fit is not: noise in the measured velocity otherwise
shrinks sigma1 and inflates sigma0), with the noise levels of the trace. A
joint compliance c in series (an isolated stage without a deflection
column) is removed from the displacement, w = s x - c y.

**The Stribeck curve.** Sliding steadily at speed |v| in direction s, LuGre's
friction is ``s F - sigma2_s |v| = Fc + (Fs - Fc) exp(-(v / vs)^2)``; vs (and
Fs, unless it is fixed from the breakaways) is fitted with Fc from the
inverse-dynamics fit, weighted by ``s_y^2 + (g'(v) s_v)^2``.

**Standard errors** (:class:`LsqFit`): the statistical part from the
Jacobian at the solution, ``s^2 (J^T J)^-1``, scaled by n / n_eff for the
autocorrelation of the filtered residuals (the same effective sample count as
the inverse-dynamics fit, per branch); the propagated part from the
inverse-dynamics estimates the fit rests on (mass, Coulomb and viscous
friction, offset: the vector p with covariance C): the solution moves with p
as ``dx/dp = -(J^T J)^-1 J^T dr/dp`` (implicit function theorem, dr/dp by
central differences), so it carries ``G C G^T`` with ``G = dx/dp``. A
sub-percent error of the sliding friction thus shows in the error bar
instead of moving the estimate unnoticed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .preprocess import Trace
from .regression import effective_fraction


# --------------------------------------------------------------------------- sliding estimates


@dataclass(frozen=True, eq=False)
class Sliding:
    """The inverse-dynamics estimates, in the symmetric form, with their covariance (internal).

    ``names`` are the mass parameters (``mass``, or ``stage_mass`` and
    ``cart_mass``), ``coulomb``, ``viscous``, ``viscous_negative`` and
    ``offset``; a per-direction solution is read as Fc = (Fc+ + Fc-) / 2,
    offset = (Fc+ - Fc-) / 2 (the same fit).
    """

    names: tuple[str, ...]
    theta: np.ndarray
    cov: np.ndarray

    @classmethod
    def from_solution(cls, names, theta, cov) -> "Sliding":
        """From a :class:`~.regression.Solution`'s names, estimates and covariance."""
        names = list(names)
        theta = np.asarray(theta, dtype=float)
        cov = np.asarray(cov, dtype=float)
        if "coulomb_negative" in names:  # per direction: to the symmetric reading
            i, j = names.index("coulomb"), names.index("coulomb_negative")
            T = np.eye(len(names))
            T[i, i] = T[i, j] = 0.5
            T[j, i], T[j, j] = 0.5, -0.5
            theta, cov = T @ theta, T @ cov @ T.T
            names[j] = "offset"
        elif "offset" not in names:
            names.append("offset")
            theta = np.append(theta, 0.0)
            cov = np.pad(cov, ((0, 1), (0, 1)))
        return cls(tuple(names), theta, cov)

    def value(self, name: str) -> float:
        """The estimate of ``name`` [SI]."""
        return float(self.theta[self.names.index(name)])

    def std_error(self, name: str) -> float:
        """Its standard error [SI]."""
        i = self.names.index(name)
        return math.sqrt(max(float(self.cov[i, i]), 0.0))

    def mass(self) -> float:
        """The total moving mass [kg]."""
        return sum(self.value(n) for n in self.names if n.endswith("mass"))


def _force_noise(tr: Trace, mass: float) -> float:
    """Noise of the measured friction force [N]: force and mass times acceleration noise.

    Never zero (a noise-free record): at least 1e-9 of the largest force.
    """
    return max(math.hypot(tr.su, mass * tr.sa), 1e-9 * float(np.max(np.abs(tr.u))), 1e-12)


def friction_force(tr: Trace, names: tuple[str, ...], p: np.ndarray) -> np.ndarray:
    """Friction on the bearing, u - inertia - offset, for the estimates ``p`` by ``names`` [N]."""
    F = tr.u.copy()
    for name, column in tr.inertia.items():
        F -= p[names.index(name)] * column
    return F - p[names.index("offset")]


def viscous(names: tuple[str, ...], p: np.ndarray, s: float) -> float:
    """Viscous friction of direction ``s`` (+1 or -1) [N s/m]."""
    return float(p[names.index("viscous" if s > 0 else "viscous_negative")])


# --------------------------------------------------------------------------- least squares


@dataclass(frozen=True, eq=False)
class LsqFit:
    """A nonlinear least-squares fit with its statistical and propagated covariance (internal).

    ``x`` the solution, ``cov`` its statistical covariance (autocorrelation
    corrected), ``G`` the sensitivity dx/dp to the fixed estimates p whose
    covariance is ``cov_p``: the propagated covariance is ``G cov_p G^T``.
    """

    x: np.ndarray
    cov: np.ndarray
    G: np.ndarray
    cov_p: np.ndarray
    n: int
    n_eff: float
    rms: float
    success: bool
    at_bound: np.ndarray

    def std_error(self, i: int) -> tuple[float, float]:
        """(statistical, propagated) standard error of component ``i``."""
        g = self.G[i]
        return (math.sqrt(max(float(self.cov[i, i]), 0.0)),
                math.sqrt(max(float(g @ self.cov_p @ g), 0.0)))


def fit_least_squares(residual: Callable[[np.ndarray, np.ndarray], np.ndarray],
                      x0, bounds, x_scale, p: np.ndarray, cov_p: np.ndarray,
                      groups: list[int]) -> LsqFit:
    """Fit ``residual(x, p)`` (weighted residuals) over x; errors of x, and of x through p.

    Parameters
    ----------
    residual : callable
        ``residual(x, p) -> ndarray``: the weighted residuals, concatenated
        over groups of consecutive samples.
    x0, bounds, x_scale
        As for :func:`scipy.optimize.least_squares`.
    p : ndarray
        The fixed estimates the residuals depend on.
    cov_p : ndarray
        Their covariance.
    groups : list of int
        Lengths of the independent stretches of residuals (branches), for
        the autocorrelation correction.

    Returns
    -------
    LsqFit
    """
    from scipy.linalg import pinvh
    from scipy.optimize import least_squares

    sol = least_squares(lambda x: residual(x, p), x0, bounds=bounds, x_scale=x_scale,
                        method="trf")
    r = sol.fun
    J = sol.jac
    n, k = len(r), len(sol.x)
    s2 = float(r @ r) / max(n - k, 1)
    JtJ_inv = pinvh(J.T @ J)
    bounds_lo, bounds_hi = (np.broadcast_to(b, (k,)) for b in bounds)
    at = (np.isclose(sol.x, bounds_lo) & np.isfinite(bounds_lo)) | \
         (np.isclose(sol.x, bounds_hi) & np.isfinite(bounds_hi))
    stretches = np.split(r, np.cumsum(groups)[:-1]) if len(groups) > 1 else [r]
    n_eff = sum(len(g) / effective_fraction(g) for g in stretches if len(g))
    cov = s2 * JtJ_inv * (n / max(n_eff, 1.0))
    # sensitivity to the fixed estimates: dx/dp = -(J^T J)^-1 J^T dr/dp
    se_p = np.sqrt(np.clip(np.diag(cov_p), 0.0, None))
    R = np.empty((n, len(p)))
    for j in range(len(p)):
        h = 1e-3 * se_p[j] if se_p[j] > 0 else 1e-6 * (abs(p[j]) + 1.0)
        dp = np.zeros(len(p))
        dp[j] = h
        R[:, j] = (residual(sol.x, p + dp) - residual(sol.x, p - dp)) / (2.0 * h)
    G = -JtJ_inv @ J.T @ R
    return LsqFit(x=sol.x, cov=cov, G=G, cov_p=cov_p, n=n, n_eff=float(n_eff),
                  rms=math.sqrt(s2), success=bool(sol.success), at_bound=at)


# --------------------------------------------------------------------------- presliding branch


@dataclass(frozen=True, eq=False)
class Branch:
    """Samples of one branch of monotonic motion in direction ``s`` (internal)."""

    idx: np.ndarray
    s: float


def extended(sliding: Sliding, extras: list[tuple[float, float, np.ndarray | None]]):
    """p = (sliding estimates, extras) and its covariance.

    Parameters
    ----------
    sliding : Sliding
        The inverse-dynamics estimates.
    extras : list of (value, variance, covariance with the sliding estimates or None)
        Further fixed estimates (taken uncorrelated with one another).

    Returns
    -------
    (ndarray, ndarray)
    """
    n = len(sliding.names)
    k = len(extras)
    C = np.zeros((n + k, n + k))
    C[:n, :n] = sliding.cov
    for i, (_, var, cov) in enumerate(extras):
        C[n + i, n + i] = var
        if cov is not None:
            C[:n, n + i] = C[n + i, :n] = cov
    return np.concatenate([sliding.theta, [e[0] for e in extras]]), C


def bristle_force(w: np.ndarray, g: np.ndarray, sigma0: float, y0: float) -> np.ndarray:
    """LuGre's bristle force along a branch, dY/dw = sigma0 (1 - Y / g), from Y(w[0]) = y0.

    Exact for a level g constant over each sample interval (its mean there):
    ``Y[k+1] = g + (Y[k] - g) exp(-sigma0 (w[k+1] - w[k]) / g)``, summed in
    closed form with cumulative sums. With g constant it is
    ``g + (y0 - g) exp(-sigma0 (w - w[0]) / g)``.
    """
    gm = 0.5 * (g[1:] + g[:-1])
    a = sigma0 * np.diff(w) / gm
    A = np.concatenate([[0.0], np.cumsum(a)])
    if np.ptp(A) < 600.0:
        c = -np.expm1(-a) * gm * np.exp(A[1:])
        return np.exp(-A) * (y0 + np.concatenate([[0.0], np.cumsum(c)]))
    Y = np.empty(len(w))  # saturated far beyond the exponent range: step by step
    Y[0] = y0
    for k in range(len(a)):
        Y[k + 1] = gm[k] + (Y[k] - gm[k]) * math.exp(-a[k])
    return Y


def fit_branches(tr: Trace, sliding: Sliding, branches: list[Branch], *,
                 fixed: dict | None = None, cov_p: np.ndarray | None = None,
                 damping: bool = True) -> LsqFit:
    """Fit the presliding-branch model to branches (shared kappa, sigma0, sigma1; Y_b each).

    Parameters
    ----------
    tr : Trace
        The record's filtered signals.
    sliding : Sliding
        The inverse-dynamics estimates (fixed, their errors propagated).
    branches : list of Branch
        The samples of each branch and its direction.
    fixed : dict, optional
        Fixed values, in this order when given: ``kappa`` = 1 / Fs [1/N] (else
        fitted), ``vs`` the Stribeck velocity [m/s]: the level then follows the
        Stribeck curve at the measured creep speed, ``g(v) = Fc + (1 / kappa -
        Fc) exp(-(v / vs)^2)`` with Fc the identified Coulomb friction (else g =
        1 / kappa on the whole branch).
    cov_p : ndarray, optional
        Covariance of p = (sliding estimates, fixed values) (:func:`extended`);
        default the sliding estimates' with the fixed values exact.
    damping : bool
        Fit sigma1 (True) or leave it out (False, sigma1 = 0).

    Returns
    -------
    LsqFit
        ``x`` is ``[kappa (if fitted), sigma0, sigma1 (if damping), Y_b...]``.
    """
    names = sliding.names
    n = len(names)
    fixed = dict(fixed or {})
    keys = [k for k in ("kappa", "vs") if k in fixed]
    p, C = extended(sliding, [(fixed[k], 0.0, None) for k in keys])
    if cov_p is not None:
        C = np.asarray(cov_p, dtype=float)
    m = sliding.mass()
    sy = _force_noise(tr, m)
    data = [(tr.x[b.idx], tr.v[b.idx], tr.u[b.idx],
             {k: c[b.idx] for k, c in tr.inertia.items()}, b.s) for b in branches]
    k_fixed = "kappa" in fixed

    def ys(pp):
        out = []
        for x, v, u, acc, s in data:
            F = u - sum(pp[names.index(k)] * c for k, c in acc.items()) - pp[names.index("offset")]
            y = s * F - viscous(names, pp, s) * s * v
            out.append((y, s * x - tr.compliance * y, s * v))
        return out

    def residual(xx, pp):
        i = 0
        if k_fixed:
            kap = pp[n + keys.index("kappa")]
        else:
            kap, i = xx[0], 1
        s0, s1 = xx[i], (xx[i + 1] if damping else 0.0)
        res = []
        for (y, w, vs), y_b in zip(ys(pp), xx[i + 1 + damping:]):
            level = 1.0 / max(kap, 1e-300)
            if "vs" in fixed:
                fc = pp[names.index("coulomb")]
                g = fc + (level - fc) * np.exp(-(vs / pp[n + keys.index("vs")]) ** 2)
            else:
                g = np.full(len(w), level)
            Y = bristle_force(w, g, s0, y_b)
            model = Y + s1 * vs * (1.0 - Y / g)
            slope = s0 * (1.0 - Y / g)  # d model / d w
            damp = s1 * (1.0 - Y / g)  # d model / d v
            res.append((y - model) / np.sqrt(sy ** 2 + (slope * tr.sx) ** 2
                                             + (damp * tr.sv) ** 2))
        return np.concatenate(res)

    y0 = ys(p)
    top = max(float(np.max(np.abs(y))) for y, _, _ in y0)
    span = max(float(np.ptp(w)) for _, w, _ in y0)
    rng = max(float(np.ptp(y)) for y, _, _ in y0)
    s0_0 = max(2.0 * rng / max(span, 1e-12), 1e-6)
    x0, lo, hi, scale = [], [], [], []
    if not k_fixed:
        x0.append(0.9 / top if top > 0 else 0.0)
        lo.append(0.0)
        hi.append(2.0 / top if top > 0 else np.inf)
        scale.append(1.0 / top if top > 0 else 1.0)
    x0.append(s0_0)
    lo.append(0.0)
    hi.append(np.inf)
    scale.append(s0_0)
    if damping:
        x0.append(0.0)
        lo.append(0.0)
        hi.append(np.inf)
        scale.append(math.sqrt(s0_0 * max(m, 1e-9)))
    for y, _, _ in y0:
        x0.append(float(y[0]))
        lo.append(-np.inf)
        hi.append(np.inf)
        scale.append(max(sy, 1e-3 * rng, 1e-12))
    x0 = np.clip(x0, lo, hi)
    return fit_least_squares(residual, x0, (np.array(lo), np.array(hi)), np.array(scale), p,
                             C, [len(b.idx) for b in branches])


# --------------------------------------------------------------------------- Stribeck curve


def fit_stribeck(tr: Trace, sliding: Sliding, idx: np.ndarray, *, static: float | None = None,
                 static_var: float = 0.0, static_cov: np.ndarray | None = None) -> LsqFit:
    """Fit the steady-state Stribeck curve to steadily sliding samples ``idx``.

    Parameters
    ----------
    tr : Trace
        The record's filtered signals.
    sliding : Sliding
        The inverse-dynamics estimates: Fc, viscous friction, mass, offset
        (fixed, their errors propagated).
    idx : ndarray of int
        The samples.
    static : float, optional
        Fs fixed [N] (from the breakaways; its variance ``static_var`` and
        covariance ``static_cov`` with the sliding estimates are propagated);
        None: fitted.
    static_var : float
        Variance of a fixed Fs [N^2].
    static_cov : ndarray, optional
        Covariance of a fixed Fs with the sliding estimates.

    Returns
    -------
    LsqFit
        ``x`` is ``[vs]`` or ``[vs, Fs]``.
    """
    names = sliding.names
    sy = _force_noise(tr, sliding.mass())
    v = tr.v[idx]
    s = np.sign(v)
    speed = np.abs(v)
    u = tr.u[idx]
    acc = {k: c[idx] for k, c in tr.inertia.items()}
    fixed = static is not None
    p, cov_p = extended(sliding, [(static, static_var, static_cov)] if fixed else [])

    def residual(xx, pp):
        vs = xx[0]
        fs_ = pp[-1] if fixed else xx[1]
        fc = pp[names.index("coulomb")]
        F = u - sum(pp[names.index(k)] * c for k, c in acc.items()) - pp[names.index("offset")]
        visc = np.where(s > 0, pp[names.index("viscous")], pp[names.index("viscous_negative")])
        y = s * F - visc * speed
        e = np.exp(-(speed / vs) ** 2)
        slope = (fs_ - fc) * e * 2.0 * speed / vs ** 2
        return (y - (fc + (fs_ - fc) * e)) / np.sqrt(sy ** 2 + (slope * tr.sv) ** 2)

    fc = sliding.value("coulomb")
    vs0 = float(np.median(speed))
    x0 = [vs0]
    lo, hi, scale = [1e-3 * vs0], [np.inf], [vs0]
    if not fixed:
        x0.append(fc + 2.0 * max(float(np.max(s * (u - sliding.value("offset")))) - fc, 1e-3))
        lo.append(-np.inf)
        hi.append(np.inf)
        scale.append(max(abs(fc), 1e-3))
    return fit_least_squares(residual, np.array(x0), (np.array(lo), np.array(hi)),
                             np.array(scale), p, cov_p, [len(idx)])
