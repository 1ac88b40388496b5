"""Progress: a run with a bar shows the step count, the simulated time and the rate,
and the first run of a process says that it compiles the kernels."""
import subprocess
import sys
import textwrap


def test_bar_with_time_and_rate_and_the_compile_notice_once():
    code = textwrap.dedent("""
        import numpy as np, tdem
        sim = tdem.Simulation(gravity=(0, -9.81), progress=True, check_interval=50)
        xs = (np.arange(10) + 0.5) * 0.02
        sim.add_particles(np.array([(x, y) for y in xs for x in xs]), 0.009,
                          contact=tdem.LinearContact(kn=1e6))
        sim.run(steps=200)
        sim.run(steps=200)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    err = out.stderr
    assert err.count("tdem: compiling kernels (the first run of a process") == 1
    assert "tdem (dt " in err and "/200" in err
    assert "t=" in err and "particle-steps/s" in err
