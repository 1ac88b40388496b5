"""Output: VTU snapshots (read back with VTK and meshio), .pvd series, monitors.h5, plots."""
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import tdem
from tdem.io import Output, plot_histories, read_monitors


def _box_of_discs(n_x=6, n_y=5, r=0.01, steps=400):
    """30 discs dropped into a box of four walls; after ``steps`` steps they rest on
    the floor and on each other."""
    law = tdem.LinearContact(kn=1e5, friction=0.4, restitution=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    rng = np.random.default_rng(3)
    xs = 0.015 + np.arange(n_x) * 0.022
    ys = 0.015 + np.arange(n_y) * 0.022
    pos = np.array([(x, y) for y in ys for x in xs]) + rng.uniform(-2e-3, 2e-3, (n_x * n_y, 2))
    sim.add_particles(pos, r, density=2500.0, contact=law,
                      velocity=rng.normal(0.0, 0.05, (n_x * n_y, 2)))
    w, h = 0.14, 0.2
    for a, b in (((0, 0), (w, 0)), ((w, 0), (w, h)), ((w, h), (0, h)), ((0, h), (0, 0))):
        sim.add_wall(a, b, contact=law)
    if steps:
        sim.run(steps=steps)
    return sim


def _vtk_read(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0
    return r.GetOutput()


def _point_array(grid, name):
    return vtk_to_numpy(grid.GetPointData().GetArray(name))


def _cell_array(grid, name):
    return vtk_to_numpy(grid.GetCellData().GetArray(name))


def _line_ends(grid):
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    ends = []
    for c in range(grid.GetNumberOfCells()):
        ids = grid.GetCell(c).GetPointIds()
        assert ids.GetNumberOfIds() == 2
        ends.append((pts[ids.GetId(0)], pts[ids.GetId(1)]))
    return np.array(ends).reshape(-1, 2, 3)


def _pvd(path):
    root = ET.parse(path).getroot()
    assert root.get("type") == "Collection"
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


@pytest.fixture(scope="module")
def settled():
    return _box_of_discs()


def test_snapshot_read_back_with_vtk_and_meshio(settled, tmp_path):
    sim = settled
    paths = sim.write_vtu(tmp_path / "s.vtu")
    assert [p.rsplit("/", 1)[-1] for p in paths] == ["s.vtu", "s_walls.vtu", "s_contacts.vtu"]
    p = sim.particles.numpy()
    n = len(p["radius"])
    assert n == 30

    g = _vtk_read(tmp_path / "s.vtu")
    assert g.GetNumberOfPoints() == n and g.GetNumberOfCells() == n
    pts = vtk_to_numpy(g.GetPoints().GetData())
    np.testing.assert_array_equal(pts[:, :2], p["position"])
    np.testing.assert_array_equal(pts[:, 2], 0.0)
    np.testing.assert_array_equal(_point_array(g, "radius"), p["radius"])
    np.testing.assert_array_equal(_point_array(g, "mass"), p["mass"])
    np.testing.assert_array_equal(_point_array(g, "omega"), p["omega"])
    np.testing.assert_array_equal(_point_array(g, "id"), np.arange(n))
    for name in ("velocity", "force", "displacement"):
        a = _point_array(g, name)
        assert a.shape == (n, 3)
        np.testing.assert_array_equal(a[:, :2], p[name])
        np.testing.assert_array_equal(a[:, 2], 0.0)
    stress = _point_array(g, "stress").reshape(n, 3, 3)
    np.testing.assert_array_equal(stress[:, :2, :2], p["stress"])
    assert np.abs(p["stress"]).max() > 0.0           # the discs are loaded
    assert np.abs(p["force"]).max() > 0.0

    m = meshio.read(tmp_path / "s.vtu")
    np.testing.assert_array_equal(m.points[:, :2], p["position"])
    np.testing.assert_array_equal(m.point_data["radius"], p["radius"])
    np.testing.assert_array_equal(m.point_data["velocity"][:, :2], p["velocity"])
    np.testing.assert_array_equal(m.point_data["force"][:, :2], p["force"])
    assert m.cells[0].type == "vertex" and len(m.cells[0].data) == n

    # walls: four lines between the endpoints, with the wall forces
    gw = _vtk_read(tmp_path / "s_walls.vtu")
    assert gw.GetNumberOfCells() == 4
    ends = _line_ends(gw)
    for k, w in enumerate(sim.walls):
        np.testing.assert_array_equal(ends[k, :, :2], w.endpoints)
        np.testing.assert_array_equal(_cell_array(gw, "force")[k, :2], w.force)
    np.testing.assert_array_equal(_cell_array(gw, "id"), np.arange(4))
    floor = sim.walls[0].force[1]
    assert floor < -0.5 * 30 * p["mass"].mean() * 9.81   # the floor carries the pile
    mw = meshio.read(tmp_path / "s_walls.vtu")
    assert mw.cells[0].type == "line" and len(mw.cells[0].data) == 4

    # contacts: one line per contact, i's centre to j's centre or to the wall point
    c = sim.contacts.numpy()
    nc = len(c["pairs"])
    assert nc > 30 and (c["pairs"][:, 1] < 0).any() and (c["pairs"][:, 1] >= 0).any()
    gc = _vtk_read(tmp_path / "s_contacts.vtu")
    assert gc.GetNumberOfCells() == nc
    np.testing.assert_array_equal(_cell_array(gc, "normal_force"), c["normal"])
    np.testing.assert_array_equal(_cell_array(gc, "shear_force"), c["shear"])
    np.testing.assert_array_equal(_cell_array(gc, "direction")[:, :2], c["direction"])
    np.testing.assert_array_equal(_cell_array(gc, "pair"), c["pairs"])
    ends = _line_ends(gc)
    i, j = c["pairs"][:, 0], c["pairs"][:, 1]
    np.testing.assert_array_equal(ends[:, 0, :2], p["position"][i])
    pp = j >= 0
    np.testing.assert_array_equal(ends[pp, 1, :2], p["position"][j[pp]])
    np.testing.assert_array_equal(ends[~pp, 1, :2], c["point"][~pp])
    mc = meshio.read(tmp_path / "s_contacts.vtu")
    np.testing.assert_array_equal(mc.cell_data["normal_force"][0], c["normal"])


def test_snapshot_without_walls_or_contacts_is_valid(tmp_path):
    law = tdem.LinearContact(kn=1e5)
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    sim.add_particles([[0.0, 0.0], [0.1, 0.0]], 0.01, contact=law)
    sim.run(steps=10)
    paths = sim.write_vtu(tmp_path / "lone.vtu")
    assert len(paths) == 3
    assert _vtk_read(tmp_path / "lone.vtu").GetNumberOfCells() == 2
    # nothing to write: one degenerate cell at the origin with zero data (meshio
    # cannot read a VTU file without cells)
    for name in ("lone_walls.vtu", "lone_contacts.vtu"):
        g = _vtk_read(tmp_path / name)
        assert g.GetNumberOfPoints() == 1 and g.GetNumberOfCells() == 1
        assert g.GetBounds() == (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    g = _vtk_read(tmp_path / "lone_contacts.vtu")
    assert g.GetCellData().GetArray("normal_force") is not None
    assert len(sim.write_vtu(tmp_path / "only.vtu", walls=False, contacts=False)) == 1
    assert not (tmp_path / "only_walls.vtu").exists()


def test_series_pvd_and_monitors(tmp_path):
    sim = _box_of_discs(steps=0)
    floor = sim.walls[0]
    sim.monitor("kinetic", lambda s: s.energy()["kinetic"], every=20)
    sim.monitor("floor/force", lambda s: floor.force, every=25)
    out = sim.output(tmp_path / "series", every=50)
    assert isinstance(out, Output)
    sim.run(steps=200)
    d = tmp_path / "series"

    steps = [s for s, _ in out.snapshots]
    assert steps == [0, 50, 100, 150, 200]
    for kind in ("particles", "walls", "contacts"):
        entries = _pvd(d / f"{kind}.pvd")
        assert len(entries) == 5
        times = np.array([t for t, _ in entries])
        assert times[0] == 0.0 and np.all(np.diff(times) > 0)
        np.testing.assert_allclose(times, np.array(steps) * sim.dt, rtol=1e-12)
        assert times[-1] == sim.time
        for t, name in entries:
            g = _vtk_read(d / name)
            if kind == "particles":
                assert g.GetNumberOfPoints() == 30
            if kind == "walls":
                assert g.GetNumberOfCells() == 4
    # the last snapshot is the state now
    last = _vtk_read(d / _pvd(d / "particles.pvd")[-1][1])
    np.testing.assert_array_equal(vtk_to_numpy(last.GetPoints().GetData())[:, :2],
                                  sim.particles.numpy()["position"])
    first = _vtk_read(d / _pvd(d / "particles.pvd")[0][1])
    np.testing.assert_array_equal(_point_array(first, "displacement"), 0.0)

    # monitors.h5 equals sim.histories()
    hist = sim.histories()
    with h5py.File(d / "monitors.h5", "r") as f:
        assert f.attrs["steps"] == 200
        np.testing.assert_array_equal(f["kinetic/time"][()], hist["kinetic"][0])
        np.testing.assert_array_equal(f["kinetic/value"][()], hist["kinetic"][1])
        np.testing.assert_array_equal(f["kinetic/step"][()], np.arange(20, 201, 20))
        assert f["floor_force"].attrs["name"] == "floor/force"
        assert f["floor_force/value"].shape == (8, 2)
        np.testing.assert_array_equal(f["floor_force/value"][()], hist["floor/force"][1])
    back = read_monitors(d / "monitors.h5")
    assert set(back) == {"kinetic", "floor/force"}
    np.testing.assert_array_equal(back["floor/force"][0], hist["floor/force"][0])

    # a rewind forgets the snapshots after it
    out.truncate(100)
    assert [s for s, _ in out.snapshots] == [0, 50, 100]
    assert len(_pvd(d / "contacts.pvd")) == 3
    assert not (d / "particles_00004.vtu").exists()
    assert (d / "particles_00002.vtu").exists()


def test_series_by_interval(tmp_path):
    sim = _box_of_discs(steps=0)
    dt = sim.dt
    interval = 7.3 * dt
    out = sim.output(tmp_path, interval=interval, contacts=False, walls=False)
    sim.run(steps=60)
    snaps = out.snapshots
    assert [s for s, _ in snaps] == [0, 8, 15, 22, 30, 37, 44, 52, 59]
    for k, (s, t) in enumerate(snaps):
        # the first step at or after k × interval
        assert t >= k * interval * (1 - 1e-12) and t - dt < k * interval
    assert not (tmp_path / "walls.pvd").exists()
    assert len(_pvd(tmp_path / "particles.pvd")) == len(snaps)


def test_series_set_up_before_particles_and_at_run_ends(tmp_path):
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    out = sim.output(tmp_path)          # neither every nor interval: end of each run
    law = tdem.LinearContact(kn=1e5)
    sim.add_particles([[0.0, 0.1], [0.05, 0.1]], 0.01, contact=law)
    sim.add_wall((-0.1, 0.0), (0.2, 0.0), contact=law)
    sim.run(steps=30)
    sim.run(steps=20)
    assert [s for s, _ in out.snapshots] == [0, 30, 50]
    entries = _pvd(tmp_path / "particles.pvd")
    assert [round(t / sim.dt) for t, _ in entries] == [0, 30, 50]
    assert (tmp_path / "monitors.h5").exists()


def test_plot_histories(tmp_path):
    sim = _box_of_discs(steps=0)
    sim.monitor("kinetic", lambda s: s.energy()["kinetic"], every=10)
    sim.monitor("floor", lambda s: s.walls[0].force, every=10)
    sim.output(tmp_path, every=1000)
    sim.run(steps=100)
    for source, png in ((sim, tmp_path / "a.png"), (tmp_path / "monitors.h5", tmp_path / "b.png")):
        out = plot_histories(source, png)
        assert out == str(png)
        data = png.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        assert len(data) > 1024
    plot_histories(sim, tmp_path / "c.png", names=["floor"])
    assert (tmp_path / "c.png").stat().st_size > 1024
    with pytest.raises(ValueError, match="names"):
        plot_histories(sim, tmp_path / "d.png", names=["nothing"])


def test_output_rejects_bad_arguments(tmp_path):
    sim = _box_of_discs(steps=0)
    with pytest.raises(ValueError, match="every"):
        sim.output(tmp_path, every=0)
    with pytest.raises(ValueError, match="interval"):
        sim.output(tmp_path, interval=-1.0)
    with pytest.raises(ValueError, match="at most one"):
        sim.output(tmp_path, every=10, interval=0.1)
