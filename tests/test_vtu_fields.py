"""What ParaView lists: each stress tensor also as named components (stress_xx,
stress_yy, stress_zz, stress_xy, equal to the tensor's), and the contact file of a
model without contacts readable by meshio (it could not read the empty file)."""
import meshio
import numpy as np

import tdem


def test_tensor_components_are_named_and_equal_the_tensor(tmp_path):
    mat = tdem.Elastic(density=2500.0, young=1e8, poisson=0.25)
    pos, rad = tdem.pack.regular(0.4, 0.4, 0.05)
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    sim.add_particles(pos, rad, material=mat, tolerance=0.05)
    sim.fix_particles(sim.particles_in(ymax=0.06), vx=0.0, vy=0.0)
    sim.run(steps=20)
    paths = sim.write_vtu(tmp_path / "s.vtu", walls=False, contacts=False)
    for path in paths:
        m = meshio.read(path)
        data = m.point_data if "stress" in m.point_data else {
            k: v[0] for k, v in m.cell_data.items()}
        st = np.asarray(data["stress"]).reshape(-1, 3, 3)
        assert np.abs(st).max() > 0.0
        for part, (a, b) in (("xx", (0, 0)), ("yy", (1, 1)), ("zz", (2, 2)), ("xy", (0, 1))):
            np.testing.assert_array_equal(data[f"stress_{part}"], st[:, a, b])


def test_contact_file_without_contacts_is_readable(tmp_path):
    sim = tdem.Simulation(gravity=(0.0, 0.0))
    sim.add_particles([[0.0, 0.0], [1.0, 0.0]], 0.1, contact=tdem.LinearContact(kn=1e6))
    paths = sim.write_vtu(tmp_path / "c.vtu", walls=False, contacts=True)
    contact_file = [p for p in map(str, paths) if p.endswith("_contacts.vtu")]
    assert contact_file
    m = meshio.read(contact_file[0])
    # meshio cannot read a VTU without cells: one degenerate placeholder, pair (-1, -1)
    assert sum(len(c.data) for c in m.cells) == 1
    assert m.cell_data["pair"][0].tolist() == [[-1, -1]]
    assert m.cell_data["normal_force"][0].tolist() == [0.0]
