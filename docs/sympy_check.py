#!/usr/bin/env python3
"""Checks that `chain derive --format json` is readable by SymPy's sympify.

For every example machine, every nominal entry and every coefficient is parsed
with sympify (with `^` read as a power, SymPy's default convert_xor); for the
gantry grinder, px..oz are compared symbolically with seed 000's Eq. 18 with
the two errata of docs/errata.md applied. Not part of the test suite:

    pip install sympy
    python3 docs/sympy_check.py
"""
import json
import pathlib
import subprocess
import sys

import sympy

ROOT = pathlib.Path(__file__).resolve().parent.parent


def derive(path):
    out = subprocess.run(
        ["cargo", "run", "--release", "--quiet", "--", "derive", str(path), "--format", "json"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    )
    return json.loads(out.stdout)


def component(doc, name):
    return sum((sympy.sympify(c) * sympy.Symbol(e) for e, c in doc["components"][name].items()),
               sympy.Integer(0))


def main():
    count = 0
    for path in sorted((ROOT / "examples" / "machines").glob("*.yaml")):
        doc = derive(path)
        for row in doc["nominal"]["rotation"]:
            for cell in row:
                sympy.sympify(cell)
                count += 1
        for cell in doc["nominal"]["position"]:
            sympy.sympify(cell)
            count += 1
        for comp in doc["components"].values():
            for expr in comp.values():
                sympy.sympify(expr)
                count += 1
        print(f"{path.name}: parsed")
    doc = derive(ROOT / "examples" / "machines" / "gantry_grinder.yaml")
    s = sympy.symbols
    x, y, z = s("x y z")
    dxx, dyx, dzx, exx, eyx, ezx = s("dxx dyx dzx exx eyx ezx")
    dxy, dyy, dzy, exy, eyy, ezy = s("dxy dyy dzy exy eyy ezy")
    dxz, dyz, dzz, exz, eyz, ezz = s("dxz dyz dzz exz eyz ezz")
    Sxy, Sxz, Syz = s("Sxy Sxz Syz")
    eq18 = {  # seed 000 Eq. 18, errata applied (px: -y*ezz; oz: -Sxy)
        "px": -dxx - z*eyx + y*ezx + dxz + dxy + y*Sxy - y*ezz,
        "py": -dyx + z*exx + x*ezx + dyz + dyy + x*Sxy,
        "pz": -dzx - y*exx - x*eyx + dzz + y*exz + dzy + y*Syz,
        "ox": -exx + exz + Syz + exy,
        "oy": -eyx + eyz + Sxz + eyy,
        "oz": -ezx + ezz + ezy - Sxy,
    }
    for name, expected in eq18.items():
        diff = sympy.simplify(component(doc, name) - expected)
        if diff != 0:
            print(f"gantry {name}: differs from corrected Eq. 18 by {diff}")
            return 1
    print(f"{count} expressions parsed by sympify; gantry equals corrected Eq. 18")
    return 0


if __name__ == "__main__":
    sys.exit(main())
