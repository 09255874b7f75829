"""Published cases the tests share: specs written from the papers' own parameters."""

from __future__ import annotations

import math


def canudas_spec(model: str = "lugre", hunting: dict | None = None, duration: str = "20 s"):
    """Canudas de Wit et al. (1995): a unit mass (0.5 + 0.5 kg) under PID (kp 3 N/m, ki 4
    N/(m s), kd 6 N s/m, D on the measurement) with Fs 1.5 N, Fc 1 N, vs 1 mm/s, sigma2 0.4
    N s/m, sigma0 1e5 N/m; a 1 m move, horizon 1000 s."""
    from fi_design.spec.file import load_spec

    return load_spec({
        "name": "Canudas de Wit et al. 1995, unit mass under PID",
        "stage": {"mass": "0.5 kg"}, "cart": {"mass": "0.5 kg"},
        "friction": {"model": model, "static": "1.5 N", "coulomb": "1 N", "stribeck_velocity": "1 mm/s",
                     "viscous": "0.4 N*s/m", "bristle_stiffness": "1e5 N/m",
                     "bristle_damping": f"{math.sqrt(1e5)} N*s/m"},
        "controller": {"gains": {"kp": "3 N/m", "ki": "4 N/(m*s)", "kd": "6 N*s/m"},
                       "derivative_on": "measurement"},
        "motion": {"moves": [{"distance": "1 m", "velocity": "1 m/s",
                              "acceleration": "10 m/s^2"}], "duration": duration},
        "requirements": {"hunting": {"horizon": "1000 s", **(hunting or {})}}})
