"""Candidate spaces: what each catalogue effect fits, within which bounds, from where.

Every applicable effect becomes a :class:`Space`: its fitted coordinates,
each mapped from u in [0, 1] to an SI value (logarithmically where the
catalogue says so), the search bounds and the physical limits the bounds may
be widened to, the starting points (a grid plus the signatures' guesses) and
each parameter's *reference*: its value in the model the search starts from
(the nominal spec value, or the effect's neutral value), against which the
fitted value's distance is measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from .. import effects as _effects
from .comparison import Comparison
from ..results.reconciliation import Lattice
from .signatures import Evidence

#: Factor a logarithmic search bound moves by when widened.
WIDEN_LOG = 10.0
#: Multiple of its span a linear search bound moves out by when widened.
WIDEN_LINEAR = 3.0


@dataclass(frozen=True)
class Coord:
    """One fitted coordinate u in [0, 1] mapped to an SI value in [lo, hi].

    Attributes
    ----------
    name : str
        Coordinate name (a parameter name, or an internal one such as
        ``scale`` or ``phase_center``).
    lo, hi : float
        Search bounds [SI].
    log : bool
        Logarithmic mapping (lo > 0).
    periodic : bool
        A phase: wraps, never "at a bound".
    limit_lo, limit_hi : float
        How far the bounds may be widened: the physical limits (a
        coefficient stays positive) or the identifiable range (a force
        limit above the peak force).
    """

    name: str
    lo: float
    hi: float
    log: bool = False
    periodic: bool = False
    limit_lo: float = -math.inf
    limit_hi: float = math.inf

    def value(self, u: float) -> float:
        """SI value of the coordinate at u."""
        if self.log:
            return float(self.lo * (self.hi / self.lo) ** u)
        return float(self.lo + (self.hi - self.lo) * u)

    def u_of(self, value: float) -> float:
        """u of an SI value, clipped to [0, 1]."""
        if self.log:
            value = min(max(value, self.lo), self.hi)
            return float(math.log(value / self.lo) / math.log(self.hi / self.lo))
        return float(min(max((value - self.lo) / (self.hi - self.lo), 0.0), 1.0))

    @property
    def step(self) -> float:
        """Finite-difference step in u (about 1e-3 relative in the value)."""
        if self.log:
            return 1e-3 / math.log(self.hi / self.lo)
        return 1e-3

    def widened(self, upper: bool) -> "Coord | None":
        """The coordinate with one bound moved out, or None when it sits at its limit."""
        if self.periodic:
            return None
        if upper:
            if self.hi >= self.limit_hi:
                return None
            hi = self.hi * WIDEN_LOG if self.log else self.hi + WIDEN_LINEAR * (self.hi - self.lo)
            return replace(self, hi=min(hi, self.limit_hi))
        if self.lo <= self.limit_lo:
            return None
        lo = self.lo / WIDEN_LOG if self.log else self.lo - WIDEN_LINEAR * (self.hi - self.lo)
        lo = max(lo, self.limit_lo)
        if self.log and lo <= 0.0:
            return None
        return replace(self, lo=lo)


@dataclass
class Space:
    """One candidate effect's fit: coordinates, mapping to parameters, starts, references.

    Attributes
    ----------
    name : str
        Effect name.
    coords : list of Coord
        Fitted coordinates (empty for an effect read from the data).
    build : callable
        Coordinate values (dict) to the effect's parameters (dict, SI).
    method : str
        ``"ls"`` (least squares from starts), ``"periodic"`` (periodogram
        peaks times a phase grid) or ``"fixed"`` (no free coordinate).
    references : dict of str to float or None
        Value of each parameter in the model the search starts from.
    starts : list of ndarray
        Starting points in u.
    quantize : float or None
        The sensor's lattice step the model's position is reported on.
    fixed : dict
        Parameters of a ``"fixed"`` space.
    from_data : bool
        The effect and its value were read from the data (the lattice test):
        that test, not the share of the gap it explains, is the evidence.
    data_error : dict
        Standard error of each value read from the data, SI.
    inactive_at : dict
        For a parameter without a model value: the value at which it stops
        acting (a force limit at the record's peak force, SI), from which its
        distance in standard errors is measured.
    """

    name: str
    coords: list
    build: Callable[[dict], dict]
    method: str = "ls"
    references: dict = field(default_factory=dict)
    starts: list = field(default_factory=list)
    quantize: float | None = None
    fixed: dict = field(default_factory=dict)
    from_data: bool = False
    data_error: dict = field(default_factory=dict)
    inactive_at: dict = field(default_factory=dict)

    def origin(self, parameter: str) -> float | None:
        """The value a parameter's distance in standard errors is measured from: where it
        stops acting (:attr:`inactive_at`), else its reference (None: no distance)."""
        return self.inactive_at.get(parameter, self.references.get(parameter))


@dataclass(frozen=True)
class Spaces:
    """The candidate spaces of one search and the effects left out.

    Attributes
    ----------
    spaces : tuple of Space
        In catalogue order.
    skipped : dict of str to str
        Effect name to the reason it was not tried.
    """

    spaces: tuple
    skipped: dict


def _same(v: dict) -> dict:
    return dict(v)


def candidate_spaces(cmp: Comparison, evidence: Evidence, names: list[str], lattice: Lattice,
                     params) -> Spaces:
    """The spaces of the effects ``names`` (catalogue order kept).

    Parameters
    ----------
    cmp : Comparison
        The comparison (record, drive, travel).
    evidence : Evidence
        Signatures and their guesses.
    names : list of str
        Effects to try.
    lattice : Lattice
        The lattice of the measured positions.
    params : PlantParameters
        Kernel parameters of the model the search starts from (references).
    """
    skipped: dict[str, str] = {}
    spaces = []
    for name in names:
        why = _not_applicable(name, cmp, lattice)
        if why:
            skipped[name] = why
            continue
        sp = _space(name, cmp, lattice, params)
        if sp is None:
            skipped[name] = "not identifiable: the force stays too small"
            continue
        sp.starts = _starts(sp, evidence.guesses.get(name, []), params)
        if sp.method == "periodic":
            sp.starts += _periodic_starts(sp, evidence, cmp, params)
        spaces.append(sp)
    return Spaces(spaces=tuple(spaces), skipped=skipped)


def _not_applicable(name: str, cmp: Comparison, lattice: Lattice) -> str:
    """Why an effect cannot be tried on this record ('' when it can)."""
    if name == "joint_damping" and not cmp.iso:
        return "not applicable: the stage has no isolator (no joint)"
    if name in ("time_delay", "force_saturation") and cmp.drive != "closed":
        return ("not applicable: an open-loop replay drives the plant with the recorded force "
                "as it is (no controller delay, no limit between them)")
    if name == "quantization":
        if cmp.drive != "closed":
            return "not applicable: no controller in an open-loop replay"
        if not lattice.found:
            return ("not in the data: " + lattice.detail if lattice.detail else
                    "not in the data: the measured position lies on no lattice")
        if not lattice.coarse:
            return ("not coarser than the noise: " + lattice.detail)
    return ""


def _space(name: str, cmp: Comparison, lattice: Lattice, params) -> Space | None:
    eff = _effects.get(name)
    ref = {p.name: _reference(p, params) for p in eff.parameters}
    if name == "mass_error":
        p = eff.parameter("stage_mass")
        lo, hi = p.bounds
        if cmp.iso:
            coords = [Coord("stage_mass", params.m1 * lo, params.m1 * hi, log=True, limit_lo=0.0),
                      Coord("cart_mass", params.m2 * lo, params.m2 * hi, log=True, limit_lo=0.0)]
            return Space(name, coords, _same, references=ref)
        m1, m2 = params.m1, params.m2
        return Space(name, [Coord("scale", lo, hi, log=True, limit_lo=0.0)],
                     lambda v: {"stage_mass": m1 * v["scale"], "cart_mass": m2 * v["scale"]},
                     references=ref)
    if name in ("position_dependent_friction", "force_ripple"):
        # The phase is fitted at the middle of the travel, x_c, where it does not trade off
        # against the period (the phase at x = 0 does, by 2 pi x_c / period).
        amp, per, _ = eff.parameters
        coords = [Coord(amp.name, amp.bounds[0], amp.bounds[1], log=amp.log, limit_lo=0.0,
                        limit_hi=0.99 if name == "position_dependent_friction" else math.inf),
                  Coord(per.name, per.bounds[0], per.bounds[1], log=per.log,
                        limit_lo=per.bounds[0], limit_hi=per.bounds[1]),
                  Coord("phase_center", -2 * math.pi, 2 * math.pi, periodic=True)]
        xc, pname = cmp.travel_center, per.name

        def build(v, pname=pname, xc=xc):
            phase = v["phase_center"] - 2 * math.pi * xc / v[pname]
            phase = float((phase + math.pi) % (2 * math.pi) - math.pi)
            return {"amplitude": v["amplitude"], pname: v[pname], "phase": phase}
        return Space(name, coords, build, method="periodic", references=ref)
    if name == "time_delay":
        p = eff.parameters[0]
        lo = max(2e-4, 0.02 / (2 * math.pi * _crossover(cmp)))
        # the lower bound stands for "no delay": a shorter one is not searched
        return Space(name, [Coord("delay", lo, p.bounds[1], log=True, limit_lo=lo)], _same,
                     references=ref)
    if name == "quantization":
        return Space(name, [], _same, method="fixed", references=ref, quantize=lattice.step,
                     fixed={"resolution": lattice.step}, from_data=True,
                     data_error={"resolution": lattice.step_error})
    if name == "force_saturation":
        p = eff.parameters[0]
        peak = float(np.max(np.abs(cmp.meas.force))) if cmp.meas.force is not None \
            else float(np.max(np.abs(cmp.nominal_force)))
        hi = min(p.bounds[1], 1.05 * peak)
        if not hi > p.bounds[0]:
            return None
        return Space(name, [Coord("limit", p.bounds[0], hi, log=True, limit_lo=1e-3,
                                  limit_hi=hi)], _same, references=ref,
                     inactive_at={"limit": peak})
    if name == "friction_asymmetry":
        coords = []
        for p in eff.parameters:
            nominal = ref[p.name]
            if nominal is not None and nominal > 0:
                coords.append(Coord(p.name, nominal * p.bounds[0], nominal * p.bounds[1],
                                    log=True, limit_lo=0.0))
            else:  # a zero nominal value: search a linear range above it
                coords.append(Coord(p.name, 0.0, 10.0, limit_lo=0.0))
        return Space(name, coords, _same, references=ref)
    coords = []
    for p in eff.parameters:
        lo, hi = p.bounds
        limit_lo = 0.0 if lo >= 0.0 else -math.inf
        coords.append(Coord(p.name, lo, hi, log=p.log, limit_lo=limit_lo))
    return Space(name, coords, _same, references=ref)


def _crossover(cmp: Comparison) -> float:
    return cmp.model.crossover


def _reference(p: _effects.Parameter, params) -> float | None:
    """The value a parameter has in the model the search starts from, or None.

    Parameters that correct a spec value (``neutral`` None) refer to the
    model's value; additive ones (a delay on top) and amplitudes refer to
    zero; periods, phases and limits have none (a force limit's distance is measured from
    the peak force, :attr:`Space.inactive_at`).
    """
    if p.periodic or (p.log and p.neutral is not None) or p.neutral == math.inf:
        return None
    if p.combine == "add":
        return 0.0
    if p.neutral is not None:
        return float(p.neutral)
    value = float(getattr(params, p.kernel_field))
    if math.isnan(value):  # per-direction friction defaults to the symmetric value
        value = float(params.Fc if p.kernel_field == "Fc_neg" else params.sigma2)
    return value


def _starts(sp: Space, guesses: list[dict], params) -> list[np.ndarray]:
    """Grid of starting points in u plus the signatures' guesses."""
    if sp.method == "fixed":
        return []
    starts: list[np.ndarray] = []
    for g in guesses:
        vals = {c.name: g.get(c.name) for c in sp.coords}
        if sp.name == "mass_error" and "scale" in vals and "stage_mass" in g:
            vals = {"scale": g["stage_mass"] / params.m1}
        if all(v is not None and math.isfinite(v) for v in vals.values()):
            starts.append(np.array([c.u_of(vals[c.name]) for c in sp.coords]))
    if sp.method == "periodic":
        return starts
    k = len(sp.coords)
    if k == 1:
        c = sp.coords[0]
        grid = list(np.linspace(0.02, 0.98, 9))
        nom = sp.references.get(c.name)
        if nom:
            grid += [c.u_of(nom * f) for f in (0.5, 0.8, 1.25, 2.0)]
        starts += [np.array([u]) for u in grid]
    elif sp.name == "cable_force":
        starts += [np.array([a, b]) for a in (0.5, 0.35, 0.65, 0.45, 0.55)
                   for b in (0.5, 0.4, 0.6, 0.47, 0.53)]
    else:
        g = np.linspace(0.1, 0.9, 5)
        starts += [np.array([a, b]) for a in g for b in g]
        refs = [sp.references.get(c.name) for c in sp.coords]
        if all(r is not None and r > 0 for r in refs):
            starts.append(np.array([c.u_of(r) for c, r in zip(sp.coords, refs)]))
    return starts


def _periodic_starts(sp: Space, evidence: Evidence, cmp: Comparison, params) -> list[np.ndarray]:
    """Starting points of a spatially periodic effect: periodogram peaks x phase grid."""
    amp_c, lam_c, ph_c = sp.coords
    peaks = [p for p in evidence.periods if lam_c.lo <= p.wavelength <= lam_c.hi][:3]
    lams = [p.wavelength for p in peaks]
    amps: list[float | None] = []
    for p in peaks:
        a = p.amplitude if cmp.has_force else None
        if a is not None and sp.name == "position_dependent_friction":
            a = a / max(params.Fc, 1e-9)
        amps.append(a)
    if not lams:
        lams = list(np.geomspace(lam_c.lo * 1.5, lam_c.hi / 1.5, 8))
        amps = [None] * len(lams)
    phases = np.linspace(-math.pi, math.pi, 12, endpoint=False)
    out = []
    for lam, a in zip(lams, amps):
        # the closed loop shapes the residual: the periodogram amplitude is only a scale
        alist = ([0.6 * a, a, 1.6 * a] if a is not None else
                 [amp_c.lo + f * (amp_c.hi - amp_c.lo) for f in (0.02, 0.06, 0.2)])
        for a_ in alist:
            for ph in phases:  # ph: the phase at the travel centre
                out.append(np.array([amp_c.u_of(min(a_, amp_c.hi)), lam_c.u_of(lam),
                                     ph_c.u_of(ph)]))
    return out
