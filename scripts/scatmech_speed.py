"""Measure pySCATMECH's cost per Mueller evaluation (one Python call per
geometry), the baseline of scripts/benchmark_models.py.  Runs only where
pySCATMECH is installed (see scripts/make_scatmech_fixtures.py)."""

import json
import sys
import time

import numpy as np
from make_scatmech_fixtures import COMMON, SDF, diffuse_model
from pySCATMECH.brdf import BRDF_Model


def models():
    yield "facet_reflection", BRDF_Model("Facet_BRDF_Model", **COMMON, substrate="(1.5,0)", type=0, sdf=SDF["gaussian"])
    yield (
        "facet_transmission",
        BRDF_Model("Facet_BRDF_Model", **COMMON, substrate="(1.5,0)", type=1, sdf=SDF["gaussian"]),
    )
    yield "smooth_diffuse", diffuse_model(1.5, 0.93)
    yield (
        "smooth_single",
        BRDF_Model(
            "First_Diffuse_BRDF_Model",
            **COMMON,
            substrate="(1.5,0)",
            phase_function="CodeWhitney_Phase_Function",
            **{"phase_function.phase_function": "Henyey_Greenstein_Phase_Function", "phase_function.plmax": 1},
        ),
    )


def main():
    rng = np.random.default_rng(0)
    count = 20000
    ti, ts, ps = rng.uniform(0, 1.4, count), rng.uniform(0, 1.4, count), rng.uniform(-np.pi, np.pi, count)
    result = {}
    for name, model in models():
        start = time.perf_counter()
        for a, b, c in zip(ti, ts, ps, strict=True):
            model.MuellerBRDF(a, b, c, 0.0, "psps")
        result[name] = (time.perf_counter() - start) / count * 1e6
    json.dump({"microseconds_per_evaluation": result}, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
