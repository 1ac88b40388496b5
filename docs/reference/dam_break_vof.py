"""A volume-of-fluid reference for Martin & Moyce's dam break (n² = 2), computed
with OpenFOAM's interFoam: the problem the particle water models solve, without
their discretisation.

The column is a = 0.3 m wide and h = 2a high against the left wall of a tank 1.5 m
long (as in ``cases.dam_break``), released at once at t = 0; water ρ = 1000 kg/m³
of kinematic viscosity ``--nu`` (1e-3 m²/s: the particle models' μ = 1 Pa·s; 1e-6:
water), air ρ = 1, ν = 1.48e-5, no surface tension; the tank's walls free-slip
(``--walls slip``, as the particle models' frictionless walls) or no-slip. The
mesh is uniform, ``--dx`` square cells, 0.7 m high (the water never reaches the
top before T = 3.5), open to the atmosphere at the top.

The front at each written time is the largest x at which the water fraction is
0.5, interpolated linearly along each row of cells, over all rows (the particle
models' front is the outermost water anywhere). Times are T = t·sqrt(2g/a),
Martin & Moyce's. Written: ``dam_break_vof_<tag>.csv`` beside this script
(columns t, T, x/a), the table ``cases.dam_break`` and the tests read.

Needs OpenFOAM (``apt-get install openfoam``; v1912 made the committed tables, on
two cores, from 18 s for the 10 mm mesh to 15 minutes for the 2.5 mm one):

    python docs/reference/dam_break_vof.py --dx 0.0025 --nu 1e-3 --walls slip   # the problem
    python docs/reference/dam_break_vof.py --dx 0.005 --nu 1e-3 --walls slip    # convergence
    python docs/reference/dam_break_vof.py --dx 0.01 --nu 1e-3 --walls slip --procs 1
    python docs/reference/dam_break_vof.py --dx 0.005 --nu 1e-6 --walls slip    # water
    python docs/reference/dam_break_vof.py --dx 0.005 --nu 1e-6 --walls noslip
    python docs/reference/dam_break_vof.py --a 0.05715 --dx 0.00095 --nu 1e-6 \
        --sigma 0.07 --walls noslip                 # water at the experiment's scale

Fronts against Martin & Moyce at T = 0.83, 1.22, 2.0, 2.55, 3.35 (measured): the
problem +13.5, +17.1, +14.0, +12.3, +10.7 % (5 mm: +14.2 … +11.3, 10 mm: +14.3 …
+11.1); water, free-slip +16.3 … +12.5, no-slip +15.4 … +12.2; at the experiment's
scale +13.4, +16.5, +13.2, +11.2, +9.5 % (tests/test_dam_break_reference.py).
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np

A = 0.3                 # column width (m) of cases.dam_break; ``--a`` scales the tank with it
G = 9.81

HEADER = """FoamFile
{{
    version 2.0; format ascii; class {cls}; location "{loc}"; object {obj};
}}
"""

FILES = {
    "system/controlDict": ("dictionary", """
application interFoam; startFrom startTime; startTime 0; stopAt endTime;
endTime {end}; deltaT 1e-5; writeControl adjustable; writeInterval {every};
purgeWrite 0; writeFormat ascii; writePrecision 7; writeCompression off;
timeFormat general; timePrecision 7; runTimeModifiable no; adjustTimeStep yes;
maxCo 0.25; maxAlphaCo 0.25; maxDeltaT 1;
"""),
    "system/blockMeshDict": ("dictionary", """
convertToMeters 1;
vertices ( (0 0 0) ({L} 0 0) ({L} {Hd} 0) (0 {Hd} 0)
           (0 0 {dz}) ({L} 0 {dz}) ({L} {Hd} {dz}) (0 {Hd} {dz}) );
blocks ( hex (0 1 2 3 4 5 6 7) ({nx} {ny} 1) simpleGrading (1 1 1) );
boundary
(
    walls {{ type wall; faces ( (0 4 7 3) (1 2 6 5) (0 1 5 4) ); }}
    atmosphere {{ type patch; faces ( (3 7 6 2) ); }}
    frontAndBack {{ type empty; faces ( (0 3 2 1) (4 5 6 7) ); }}
);
"""),
    "system/setFieldsDict": ("dictionary", """
defaultFieldValues ( volScalarFieldValue alpha.water 0 );
regions ( boxToCell {{ box (-1 -1 -1) ({a} {h} 1); fieldValues ( volScalarFieldValue alpha.water 1 ); }} );
"""),
    "system/fvSchemes": ("dictionary", """
ddtSchemes {{ default Euler; }}
gradSchemes {{ default Gauss linear; }}
divSchemes
{{
    div(rhoPhi,U) Gauss linearUpwind grad(U);
    div(phi,alpha) Gauss vanLeer;
    div(phirb,alpha) Gauss linear;
    div(((rho*nuEff)*dev2(T(grad(U))))) Gauss linear;
}}
laplacianSchemes {{ default Gauss linear corrected; }}
interpolationSchemes {{ default linear; }}
snGradSchemes {{ default corrected; }}
"""),
    "system/fvSolution": ("dictionary", """
solvers
{{
    "alpha.water.*" {{ nAlphaCorr 2; nAlphaSubCycles 1; cAlpha 1; MULESCorr yes;
        nLimiterIter 5; solver smoothSolver; smoother symGaussSeidel; tolerance 1e-8; relTol 0; }}
    "pcorr.*" {{ solver PCG; preconditioner DIC; tolerance 1e-5; relTol 0; }}
    p_rgh {{ solver PCG; preconditioner DIC; tolerance 1e-7; relTol 0.05; }}
    p_rghFinal {{ $p_rgh; relTol 0; }}
    U {{ solver smoothSolver; smoother symGaussSeidel; tolerance 1e-6; relTol 0; }}
}}
PIMPLE {{ momentumPredictor no; nOuterCorrectors 1; nCorrectors 3; nNonOrthogonalCorrectors 0; }}
relaxationFactors {{ equations {{ ".*" 1; }} }}
"""),
    "system/decomposeParDict": ("dictionary", """
numberOfSubdomains {procs}; method simple; coeffs {{ n ({procs} 1 1); }}
"""),
    "constant/g": ("uniformDimensionedVectorField", """
dimensions [0 1 -2 0 0 0 0]; value (0 -{g} 0);
"""),
    "constant/transportProperties": ("dictionary", """
phases (water air);
water {{ transportModel Newtonian; nu {nu}; rho 1000; }}
air {{ transportModel Newtonian; nu 1.48e-05; rho 1; }}
sigma {sigma};
"""),
    "constant/turbulenceProperties": ("dictionary", """
simulationType laminar;
"""),
    "0/U": ("volVectorField", """
dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);
boundaryField
{{
    walls {{ type {wall}; }}
    atmosphere {{ type pressureInletOutletVelocity; value uniform (0 0 0); }}
    frontAndBack {{ type empty; }}
}}
"""),
    "0/p_rgh": ("volScalarField", """
dimensions [1 -1 -2 0 0 0 0]; internalField uniform 0;
boundaryField
{{
    walls {{ type fixedFluxPressure; value uniform 0; }}
    atmosphere {{ type totalPressure; p0 uniform 0; }}
    frontAndBack {{ type empty; }}
}}
"""),
    "0/alpha.water": ("volScalarField", """
dimensions [0 0 0 0 0 0 0]; internalField uniform 0;
boundaryField
{{
    walls {{ type zeroGradient; }}
    atmosphere {{ type inletOutlet; inletValue uniform 0; value uniform 0; }}
    frontAndBack {{ type empty; }}
}}
"""),
}


def time_scale(a=A):
    """t = T / sqrt(2g/a): Martin & Moyce's time for n² = 2."""
    return 1.0 / math.sqrt(2.0 * G / a)


def tank(a):
    """The tank's length and the mesh's height for a column of width a."""
    return 5.0 * a, 7.0 / 3.0 * a


def write_case(folder, a, dx, nu, sigma, walls, end, every, procs):
    length, height = tank(a)
    nx, ny = int(round(length / dx)), int(round(height / dx))
    values = dict(L=length, Hd=height, dz=dx, nx=nx, ny=ny, a=a, h=2.0 * a, g=G, nu=nu,
                  sigma=sigma, wall="slip" if walls == "slip" else "noSlip", end=end,
                  every=every, procs=procs)
    for name, (cls, body) in FILES.items():
        path = os.path.join(folder, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        loc = os.path.dirname(name)
        with open(path, "w") as f:
            f.write(HEADER.format(cls=cls, loc=loc, obj=os.path.basename(name)))
            f.write(body.format(**values))
    return nx, ny


def read_alpha(path, n):
    """The cells' water fractions from an ascii volScalarField."""
    text = open(path).read()
    m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s+(\d+)\s*\(", text)
    if m is None:
        m = re.search(r"internalField\s+uniform\s+([-0-9.eE+]+)", text)
        return np.full(n, float(m.group(1)))
    count = int(m.group(1))
    body = text[m.end():text.index(")", m.end())]
    values = np.array(body.split(), dtype=float)
    if count != n or values.size != n:
        raise ValueError(f"{path}: {values.size} values, expected {n}")
    return values


def front(alpha, nx, ny, dx, length):
    """The largest x at which alpha = 0.5 on any row (linear along the row)."""
    grid = alpha.reshape(ny, nx)
    best = 0.0
    for row in grid:
        wet = np.nonzero(row >= 0.5)[0]
        if wet.size == 0:
            continue
        i = wet[-1]
        x = (i + 0.5) * dx
        if i + 1 < nx:
            a0, a1 = row[i], row[i + 1]
            x += dx * (a0 - 0.5) / (a0 - a1)
        else:
            x = length
        best = max(best, x)
    return best


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dx", type=float, default=0.0025, help="cell size (m)")
    p.add_argument("--nu", type=float, default=1e-3, help="water's kinematic viscosity (m²/s)")
    p.add_argument("--walls", choices=("slip", "noslip"), default="slip")
    p.add_argument("--a", type=float, default=A,
                   help="column width (m); the tank is 5a long (Martin & Moyce: 0.05715)")
    p.add_argument("--sigma", type=float, default=0.0, help="surface tension (N/m)")
    p.add_argument("--until", type=float, default=3.5, help="last T = t·sqrt(2g/a)")
    p.add_argument("--procs", type=int, default=2, help="MPI processes")
    p.add_argument("--foam", default="/usr/share/openfoam/etc/bashrc",
                   help="OpenFOAM's environment script")
    p.add_argument("--work", default=os.path.join("out", "dam_break_vof"))
    args = p.parse_args(argv)
    if args.dx <= 0.0 or args.dx > 0.05:
        p.error(f"--dx must be in (0, 0.05] m, got {args.dx}")
    if args.procs < 1:
        p.error(f"--procs must be at least 1, got {args.procs}")
    if args.until <= 0.0:
        p.error(f"--until must be positive, got {args.until}")
    if args.a <= 0.0:
        p.error(f"--a must be positive, got {args.a}")
    if args.sigma < 0.0:
        p.error(f"--sigma must not be negative, got {args.sigma}")
    if args.nu <= 0.0:
        p.error(f"--nu must be positive, got {args.nu}")
    tag = f"dx{args.dx * 1000:g}mm_nu{args.nu:g}_{args.walls}"
    if args.a != A or args.sigma:
        tag = f"a{args.a * 1000:g}mm_sigma{args.sigma:g}_" + tag
    folder = os.path.join(args.work, tag)
    shutil.rmtree(folder, ignore_errors=True)
    end = args.until * time_scale(args.a)
    every = 0.0025 * time_scale(args.a) / time_scale()
    nx, ny = write_case(folder, args.a, args.dx, args.nu, args.sigma, args.walls, end, every,
                        args.procs)

    def run(*cmd):
        line = " ".join(cmd)
        print("+", line, flush=True)
        name = cmd[0] if cmd[0] != "mpirun" else cmd[-2]
        with open(os.path.join(folder, f"log.{name}"), "w") as log:
            subprocess.run(["bash", "-c", f". {args.foam} && {line}"], cwd=folder,
                           stdout=log, stderr=subprocess.STDOUT, check=True)

    run("blockMesh")
    run("setFields")
    if args.procs > 1:
        run("decomposePar")
        run("mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(args.procs),
            "interFoam", "-parallel")
        run("reconstructPar")
    else:
        run("interFoam")
    rows = []
    for name in os.listdir(folder):
        try:
            t = float(name)
        except ValueError:
            continue
        alpha = read_alpha(os.path.join(folder, name, "alpha.water"), nx * ny)
        rows.append((t, t / time_scale(args.a),
                     front(alpha, nx, ny, args.dx, tank(args.a)[0]) / args.a))
    rows.sort()
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, f"dam_break_vof_{tag}.csv")
    with open(out, "w") as f:
        f.write(f"# interFoam, dx = {args.dx} m, water nu = {args.nu} m2/s, {args.walls} walls,"
                f" surface tension {args.sigma} N/m; a = {args.a} m, h = 2a, tank 5a long;"
                " front: largest x with alpha = 0.5\n")
        f.write("t,T,x_over_a\n")
        for t, T, z in rows:
            f.write(f"{t:.6f},{T:.5f},{z:.5f}\n")
    print(f"wrote {out} ({len(rows)} times)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
