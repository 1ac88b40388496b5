"""tdem.plot_history: the lines of the figure are the recorded histories, monitors of
one unit share a panel whose axis names the unit, and the legend names the monitors."""
import numpy as np
import pytest

import tdem
from tdem.plot import monitor_unit


@pytest.fixture(scope="module")
def pile(tmp_path_factory):
    out = tmp_path_factory.mktemp("pile")
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    law = tdem.LinearContact(kn=1e6, friction=0.5, restitution=0.5)
    xy = np.stack(np.meshgrid(np.arange(4), np.arange(4)), -1).reshape(-1, 2) * 0.025 + 0.02
    sim.add_particles(xy, 0.01, density=2500, contact=law)
    floor = sim.add_wall((0.0, 0.0), (0.2, 0.0), contact=law)
    sim.monitor("floor_force", lambda s: floor.force[1], every=50)
    sim.monitor("wall_force_xy", lambda s: floor.force, every=100)
    sim.monitor("kinetic_energy", lambda s: s.energy()["kinetic"], every=50)
    sim.monitor("mean_speed", lambda s: np.linalg.norm(s.particles.numpy()["velocity"],
                                                        axis=1).mean(), every=50)
    sim.monitor("count", lambda s: s.n_particles, every=100)
    sim.output(out, every=10_000)
    sim.run(steps=1000)
    return sim, out


def test_monitor_units_from_names():
    table = {"floor_force": "N/m", "blade_Fx": "N/m", "wall_loads": "N/m", "sigma_v": "Pa",
             "plate_stress": "Pa", "P4 pressure": "Pa", "kinetic_energy": "J/m",
             "top_uy": "m", "shear0_width": "m", "mean_speed": "m/s", "F_H_over_F_V": "",
             "axial_strain": "", "load [kN]": "kN", "x (mm)": "mm", "omega_3": "rad/s",
             "count": None, "P1": None}
    assert {k: monitor_unit(k) for k in table} == table


def test_lines_equal_the_recorded_histories(pile, tmp_path):
    sim, out = pile
    hist = sim.histories()
    png = tmp_path / "h.png"
    fig = tdem.plot_history(sim, out=png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    axes = fig.axes
    # force (floor_force, wall_force_xy[0], [1]), energy, velocity, count (its own)
    assert len(axes) == 4
    labels = [[ln.get_label() for ln in ax.lines] for ax in axes]
    assert labels == [["floor_force", "wall_force_xy[0]", "wall_force_xy[1]"],
                      ["kinetic_energy"], ["mean_speed"], ["count"]]
    assert [ax.get_ylabel() for ax in axes] == ["force (N/m)", "energy (J/m)",
                                                "velocity (m/s)", "count"]
    assert axes[-1].get_xlabel() == "time (s)"
    for ax in axes:
        assert [t.get_text() for t in ax.get_legend().get_texts()] == \
            [ln.get_label() for ln in ax.lines]
    lines = {ln.get_label(): ln for ax in axes for ln in ax.lines}
    t, v = hist["floor_force"]
    assert len(t) == 20                      # every 50 steps of 1000
    np.testing.assert_allclose(lines["floor_force"].get_xdata(), t, rtol=0, atol=0)
    np.testing.assert_allclose(lines["floor_force"].get_ydata(), v, rtol=0, atol=0)
    t, v = hist["wall_force_xy"]
    assert np.asarray(v).shape == (10, 2)
    for c in range(2):
        np.testing.assert_allclose(lines[f"wall_force_xy[{c}]"].get_ydata(),
                                   np.asarray(v)[:, c], rtol=0, atol=0)
    # the floor receives the pile's weight (downwards) at the end, within 20 %
    weight = sim.particles.numpy()["mass"].sum() * 9.81
    assert lines["floor_force"].get_ydata()[-1] == pytest.approx(-weight, rel=0.2)
    np.testing.assert_allclose(lines["count"].get_ydata(), 16.0)


def test_from_the_file_names_units_and_panels(pile, tmp_path):
    sim, out = pile
    hist = sim.histories()
    # the folder (its monitors.h5) gives the same numbers as the simulation
    fig = tdem.plot_history(out, names=["kinetic_energy", "floor_force"], out=None,
                            units={"floor_force": "N"}, panels="monitor")
    assert [ax.get_ylabel() for ax in fig.axes] == ["energy (J/m)", "force (N)"]
    for ax, name in zip(fig.axes, ["kinetic_energy", "floor_force"]):
        np.testing.assert_allclose(ax.lines[0].get_xdata(), hist[name][0], rtol=1e-15)
        np.testing.assert_allclose(ax.lines[0].get_ydata(), hist[name][1], rtol=1e-15)
    fig = tdem.plot_history({"a": ([0.0, 1.0], [2.0, 3.0]), "b": ([0.0], [1.0])},
                            units={"a": "kPa", "b": "kPa"}, out=tmp_path / "d.pdf")
    assert len(fig.axes) == 1 and fig.axes[0].get_ylabel() == "stress (kPa)"
    assert (tmp_path / "d.pdf").stat().st_size > 1000
    with pytest.raises(ValueError, match="names"):
        tdem.plot_history(sim, names=["nothing"], out=None)
    with pytest.raises(ValueError, match="units"):
        tdem.plot_history(sim, units={"nothing": "N"}, out=None)
    with pytest.raises(ValueError, match="monitor file"):
        tdem.plot_history(tmp_path / "none", out=None)
