"""Call fi_design from a script: step 3 of the guideline over a few isolator strokes.

A CAD or automation script varies a design parameter, re-validates the spec and
reads the numbers it needs from the result. Here the stroke of the isolator
goes from 0.1 mm to 0.5 mm; for each stroke the drive stiffness is left open so
that step 3 chooses it, and the script prints the maximum drive stiffness
k_max = Fs / stroke and the crossover the controller can reach. The linear
steps alone (``confirm=False``) do not simulate the stage, so the verdict's
status is NOT_CONFIRMED: a design that was not simulated never passes.

Run from anywhere:  python examples/cad_loop.py
"""

from __future__ import annotations

from pathlib import Path

import fi_design

HERE = Path(__file__).resolve().parent


def main() -> None:
    # The paper-like stage, read and validated once (units converted to SI).
    base_spec = fi_design.load_spec(HERE / "paper_setup.yaml")
    print(f"{base_spec.name}: Fs = {base_spec.friction.static:.3g} N, "
          f"m1 + m2 = {base_spec.total_mass:.3g} kg")

    print(f"{'stroke [mm]':>12} {'k_max [N/m]':>12} {'k [N/m]':>10} {'achievable fc [Hz]':>19}"
          f"  status")
    for stroke_mm in (0.1, 0.2, 0.3, 0.5):
        # values at dotted paths, as the YAML file takes them (strings with units or SI
        # numbers), validated again: fi_design.SpecError names the path of a bad one
        spec = fi_design.with_values(base_spec, {
            "isolator.stroke": f"{stroke_mm} mm",
            "isolator.stiffness": None,   # let step 3 choose k
            "isolator.damping": None})    # default: the joint mode's damping ratio
        result = fi_design.design(spec, confirm=False).to_dict()  # linear steps only
        stiffness = result["stiffness"]
        crossover = result["crossover"]
        print(f"{stroke_mm:>12.2f} {stiffness['maximum']:>12.0f} {stiffness['chosen']:>10.0f} "
              f"{crossover['achievable']:>19.3g}  {result['verdict']['status']}")

    # The spec resolved once into a model (every default filled in); model.at gives
    # the same stage with a value changed, checked like the spec (SpecError otherwise).
    faster = fi_design.resolve(base_spec).at(crossover=15.0)
    result = fi_design.design(faster, confirm=False).to_dict()
    print(f"crossover 15 Hz: achievable {result['crossover']['achievable']:.3g} Hz, "
          f"limited by {result['crossover']['limited_by'] or 'nothing'}")


if __name__ == "__main__":
    main()
