"""One conformance test over every entry of the effects catalogue.

Like scikit-learn's ``parametrize_with_checks``: each effect, at its neutral
values, leaves the simulation bit-identical; at a non-neutral value it changes
it; it round-trips through YAML; its parameters are documented with units
and bounds.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml

from fi_design import effects as fx
from fi_design.kernel.layout import PlantParameters
from fi_design.model import resolve
from fi_design.simulation.run import simulate
from fi_design.spec import EFFECT_MODELS
from fi_design.spec.file import load_spec, origin
from fi_design.spec.units import KNOWN_UNITS

#: A clearly non-neutral value per effect (SI), chosen to matter on the paper setup.
ACTIVE = {
    "viscous_friction": {"viscous": 60.0},
    "stribeck_velocity": {"stribeck_velocity": 1e-3},
    "position_dependent_friction": {"amplitude": 0.3, "wavelength": 2e-3, "phase": 0.5},
    "force_ripple": {"amplitude": 0.5, "pitch": 3e-3, "phase": 0.2},
    "cable_force": {"stiffness": 80.0, "preload": 0.3},
    "time_delay": {"delay": 3e-3},
    "quantization": {"resolution": 5e-6},
    "force_saturation": {"limit": 2.0},
    "mass_error": {"stage_mass": 2.0, "cart_mass": 0.5},
    "joint_damping": {"damping": 20.0},
    "force_offset": {"offset": 0.8},
    "friction_asymmetry": {"coulomb_negative": 2.0, "viscous_negative": 40.0},
}


def neutral_values(effect: fx.Effect, params: PlantParameters) -> dict:
    """The entry that sets every parameter to its neutral value."""
    out = {}
    for p in effect.parameters:
        if p.neutral is None:
            out[p.name] = params.value(p.kernel_field)
        elif p.combine == "add":
            out[p.name] = 0.0
        elif math.isinf(p.neutral):  # a spec holds finite numbers: a limit never reached
            out[p.name] = 1e12
        else:
            out[p.name] = p.neutral
    return out


def entry(name: str, values: dict):
    return EFFECT_MODELS[name].model_validate({"type": name, **values})


def test_catalogue_matches_design_md():
    assert fx.EFFECT_NAMES == tuple(ACTIVE)
    assert len(fx.EFFECT_NAMES) == 12


@pytest.mark.parametrize("name", fx.EFFECT_NAMES)
def test_effect_is_well_formed(name):
    effect = fx.get(name)
    assert effect.description
    kernel = {f for f in PlantParameters.__dataclass_fields__}
    for p in effect.parameters:
        assert p.unit in KNOWN_UNITS and p.description
        assert p.kernel_field in kernel
        lo, hi = p.bounds
        assert lo < hi
        assert p.combine in ("set", "add")


_WITHIN = {"gt": lambda x, v: x > v, "ge": lambda x, v: x >= v, "lt": lambda x, v: x < v,
           "le": lambda x, v: x <= v}


@pytest.mark.parametrize("name", fx.EFFECT_NAMES)
def test_fit_bounds_and_neutral_value_are_physically_possible(name):
    """A fit never searches, and the neutral value never sets, what a spec entry refuses."""
    for p in fx.get(name).parameters:
        values = [] if p.relative else list(p.bounds)
        if p.neutral is not None and math.isfinite(p.neutral):
            values.append(p.neutral)
        for op, limit in p.limits:
            assert all(_WITHIN[op](x, limit) for x in values), (p.name, op, limit, values)


#: Every effect on both plants, except joint damping, which needs a joint.
PLANT_CASES = [(n, iso) for n in fx.EFFECT_NAMES for iso in (True, False)
               if not (n == "joint_damping" and not iso)]


@pytest.mark.parametrize("name, isolated", PLANT_CASES)
def test_neutral_effect_leaves_the_simulation_bit_identical(paper_spec, name, isolated):
    base = simulate(paper_spec, isolated=isolated)
    params = resolve(paper_spec).plant(isolated)
    neutral = entry(name, neutral_values(fx.get(name), params))
    r = simulate(paper_spec, isolated=isolated, effects=(neutral,))
    assert np.array_equal(r.position, base.position)
    assert np.array_equal(r.force, base.force)


@pytest.mark.parametrize("name", fx.EFFECT_NAMES)
def test_active_effect_changes_the_simulation(paper_spec, name):
    isolated = True
    base = simulate(paper_spec, isolated=isolated)
    r = simulate(paper_spec, isolated=isolated, effects=(entry(name, ACTIVE[name]),))
    assert r.success, r.message
    assert r.effects == (name,)
    assert np.max(np.abs(r.position - base.position)) > 1e-7


@pytest.mark.parametrize("name", fx.EFFECT_NAMES)
def test_effect_round_trips_through_yaml(paper_spec, tmp_path, name):
    raw = copy.deepcopy(origin(paper_spec).raw)
    raw["effects"] = [{"type": name, **ACTIVE[name]}]
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(raw))
    spec = load_spec(path)
    (e,) = spec.effects
    assert e.type == name
    for k, v in ACTIVE[name].items():
        assert getattr(e, k) == pytest.approx(v)
    # and back: dump the validated entry, read it again
    raw["effects"] = [e.model_dump()]
    path.write_text(yaml.safe_dump(raw))
    assert load_spec(path).effects == spec.effects


def test_effects_with_units_in_yaml(paper_spec):
    raw = copy.deepcopy(origin(paper_spec).raw)
    raw["effects"] = [{"type": "time_delay", "delay": "1.5 ms"},
                      {"type": "position_dependent_friction", "amplitude": 0.2,
                       "wavelength": "2 mm", "phase": "90 deg"}]
    spec = load_spec(raw)
    assert spec.effects[0].delay == pytest.approx(1.5e-3)
    assert spec.effects[1].wavelength == pytest.approx(2e-3)
    assert spec.effects[1].phase == pytest.approx(math.pi / 2)


def test_delay_effect_adds_to_the_controller_delay(paper_spec):
    raw = copy.deepcopy(origin(paper_spec).raw)
    raw["controller"]["delay"] = "1 ms"
    spec = load_spec(raw)
    p = resolve(spec).at(effects=(entry("time_delay", {"delay": 2e-3}),)).plant(True)
    assert p.delay == pytest.approx(3e-3)


def test_effect_set_refuses_colliding_effects():
    both = fx.get("time_delay") + fx.get("cable_force")
    assert both.names == ("time_delay", "cable_force")
    clash = fx.Effect("other_delay", "another way to set the delay",
                      (fx.Parameter("delay", "s", "delay", "delay", (0.0, 1.0)),))
    with pytest.raises(ValueError, match="both set 'delay'"):
        fx.get("time_delay") + clash


def test_unknown_effect_name_is_a_clear_key_error():
    with pytest.raises(KeyError, match="known: viscous_friction"):
        fx.get("cogging")
