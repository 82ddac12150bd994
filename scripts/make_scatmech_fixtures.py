"""Regenerate the SCATMECH reference fixtures in tests/fixtures/.

Needs NIST SCATMECH's Python binding, which is *not* a project dependency
(it compiles C++ for about 20 minutes):

    python3 -m venv /tmp/scatmech && /tmp/scatmech/bin/pip install "numpy<2" pyscatmech
    /tmp/scatmech/bin/python scripts/make_scatmech_fixtures.py

Each case records the model, its parameters, the geometry (radians) and the
Mueller BRDF returned by ``BRDF_Model.MuellerBRDF(thetai, thetas, phis, 0,
"psps")``, with the fixtures' model parameters (lambda 0.532, substrate
(n,0), No_StackModel).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys

import numpy as np
from pySCATMECH.brdf import BRDF_Model

COMMON = {"lambda": 0.532, "stack": "No_StackModel"}
SDF = {
    "gaussian": "Gaussian_Slope_Distribution_Function",
    "exponential": "Exponential_Slope_Distribution_Function",
}


#: Normal exit (θs = 0) and normal incidence (θi = 0) at azimuths other than
#: 0 and π, where the polarization basis of the normal ray is the limit along
#: φs; each normal-exit θi also appears at φs = 0, its twin in the fixed basis.
NORMAL_EDGES = [
    (0.0488, 0.0, -0.0708),
    (0.0488, 0.0, 0.0),
    (0.3, 0.0, 0.7),
    (0.3, 0.0, 0.0),
    (0.9, 0.0, -1.9),
    (0.9, 0.0, 2.6),
    (0.9, 0.0, 0.0),
    (0.6, 0.0, np.pi / 2),
    (0.6, 0.0, 0.0),
    (1.2, 0.0, -2.3),
    (1.2, 0.0, 0.0),
    (0.0, 0.0, 0.7),
    (0.0, 0.0, -2.2),
    (0.0, 0.2, 1.1),
    (0.0, 0.8, -2.4),
    (0.0, 1.3, 3.0),
    (0.0, 0.5, -np.pi / 2),
]


def geometries(rng, count, max_theta=1.45):
    """Random geometries plus the edges: normal incidence, normal exit (φ = 0),
    in-plane (φ = 0 and π exactly), the specular and retro directions,
    near-grazing angles, and NORMAL_EDGES."""
    ti = list(rng.uniform(0, max_theta, count))
    ts = list(rng.uniform(0, max_theta, count))
    ps = list(rng.uniform(-np.pi, np.pi, count))
    edges = [
        (0.0, 0.5, 0.7),
        (0.0, 0.0, 0.0),
        (0.4, 0.0, 0.0),
        (1.0472, 1.0472, 0.0),
        (1.0472, 1.0472, np.pi),
        (0.3, 0.9, np.pi),
        (0.9, 0.3, 0.0),
        (1.5533, 0.5, 0.2),
        (0.5, 1.5533, 2.0),
        (1.5533, 1.5533, 0.0),
    ]
    for a, b, c in edges + NORMAL_EDGES:
        ti.append(a)
        ts.append(b)
        ps.append(c)
    return np.array(ti), np.array(ts), np.array(ps)


def evaluate(model, ti, ts, ps):
    return np.array([np.array(model.MuellerBRDF(a, b, c, 0.0, "psps")) for a, b, c in zip(ti, ts, ps, strict=True)])


def case(name, params, model, ti, ts, ps):
    return {
        "model": name,
        "params": params,
        "theta_i": ti.tolist(),
        "theta_s": ts.tolist(),
        "phi_s": ps.tolist(),
        "mueller": evaluate(model, ti, ts, ps).tolist(),
    }


def diffuse_model(n, rho):
    return BRDF_Model(
        "Diffuse_Subsurface_BRDF_Model",
        **COMMON,
        substrate=f"({n},0)",
        reflectance="Table_Reflectance",
        **{"reflectance.table": repr(rho)},
    )


def scatmech_rbar(n):
    """SCATMECH's own r̄ (its 0.2° sum), backed out of two of its BRDFs:
    f ∝ ρ/(1 - ρ r̄), so q = f(ρ=1)/f(ρ=½) = 2(1 - r̄/2)/(1 - r̄)."""
    f1 = np.array(diffuse_model(n, 1.0).MuellerBRDF(0.0, 0.0, 0.0, 0.0, "psps"))[0][0]
    f2 = np.array(diffuse_model(n, 0.5).MuellerBRDF(0.0, 0.0, 0.0, 0.0, "psps"))[0][0]
    q = f1 / f2
    return (q - 2.0) / (q - 1.0)


def build(count, seed):
    rng = np.random.default_rng(seed)
    cases = []
    for kind, typ in (("facet_reflection", 0), ("facet_transmission", 1)):
        for dist, sdf in SDF.items():
            for n in (1.5, 1.33):
                for slope in (0.1, 0.5, 2.0):
                    model = BRDF_Model(
                        "Facet_BRDF_Model",
                        **COMMON,
                        substrate=f"({n},0)",
                        type=typ,
                        sdf=sdf,
                        **{"sdf.s": slope},
                    )
                    params = {"n": n, "slope": slope, "distribution": dist}
                    cases.append(case(kind, params, model, *geometries(rng, count)))
    for n in (1.5, 1.33, 2.0):
        rbar = scatmech_rbar(n)
        for rho in (0.93, 0.5, 1.0):
            c = case("smooth_diffuse", {"n": n, "rho": rho}, diffuse_model(n, rho), *geometries(rng, count))
            c["scatmech_rbar"] = rbar
            cases.append(c)
    for n in (1.5, 1.33):
        for g in (0.0, 0.3, -0.5, 0.9):
            model = BRDF_Model(
                "First_Diffuse_BRDF_Model",
                **COMMON,
                substrate=f"({n},0)",
                phase_function="CodeWhitney_Phase_Function",
                **{
                    "phase_function.phase_function": "Henyey_Greenstein_Phase_Function",
                    "phase_function.phase_function.g": g,
                    "phase_function.plmax": 1,
                    "phase_function.pcmax": 0,
                    "phase_function.s": 0,
                    "phase_function.log_scattering": 0,
                    "phase_function.log_absorption": -40,
                },
            )
            cases.append(case("smooth_single", {"n": n, "g": g}, model, *geometries(rng, count)))
    return cases


def _files(here):
    """lut/lutfiles/files.py on its own: it needs only the standard library, while
    this script runs in SCATMECH's venv, which lacks lut's dependencies."""
    spec = importlib.util.spec_from_file_location("paint_lut_files", os.path.join(here, "..", "lut", "files.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.join(here, "..", "tests", "fixtures", "scatmech_reference.json")
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=default, help="output JSON file (default: %(default)s)")
    parser.add_argument("--count", type=int, default=30, help="random geometries per case (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=20261122, help="random seed (default: %(default)s)")
    args = parser.parse_args(argv)
    data = {
        "generator": "scripts/make_scatmech_fixtures.py",
        "scatmech": "pySCATMECH (pip pyscatmech 0.1.10)",
        "cases": build(args.count, args.seed),
    }
    out = os.path.abspath(args.out)
    _files(here).atomic_write_text(out, json.dumps(data, separators=(",", ":")))
    print(f"wrote {len(data['cases'])} cases to {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
