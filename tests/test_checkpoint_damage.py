"""A damaged checkpoint is refused with a ValueError (tdem.InputError) naming the
file and what is wrong, instead of h5py's OSError, a KeyError, a zero-padded state or
NaN positions that load and run."""
import json
import os
import shutil

import h5py
import numpy as np
import pytest

import tdem


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    law = tdem.LinearContact(kn=1e5, friction=0.5)
    sim = tdem.Simulation(gravity=(0.0, -9.81), progress=False)
    xs = (np.arange(6) + 0.5) * 0.025
    pos = np.array([(x, y + 0.03) for y in xs for x in xs])[:30]
    sim.add_particles(pos, 0.01, density=2500.0, contact=law)
    sim.add_wall((0.0, 0.0), (0.15, 0.0), contact=law)
    sim.fix_particles([0], vx=0.0)
    sim.run(steps=50)
    path = tmp_path_factory.mktemp("ck") / "good.h5"
    sim.save(path)
    return path


def _copy(saved, tmp_path, name="bad.h5"):
    p = tmp_path / name
    shutil.copy(saved, p)
    return p


def _refused(path, pattern):
    with pytest.raises(ValueError, match=pattern) as e:
        tdem.Simulation.load(path)
    assert isinstance(e.value, tdem.InputError)
    assert str(path) in str(e.value)
    return str(e.value)


def test_the_undamaged_checkpoint_loads(saved):
    sim = tdem.Simulation.load(saved)
    assert sim.n_particles == 30 and sim.steps == 50


def test_truncated_file(saved, tmp_path):
    p = _copy(saved, tmp_path)
    size = os.path.getsize(p)
    with open(p, "r+b") as f:
        f.truncate(size // 2)
    _refused(p, r"is not a readable HDF5 file \(truncated or damaged\?\)|is damaged: cannot read")


def test_random_bytes(tmp_path):
    p = tmp_path / "random.h5"
    p.write_bytes(np.random.default_rng(1).bytes(4096))
    _refused(p, r"path: .*random\.h5' is not a readable HDF5 file \(truncated or damaged\?\)")


def test_missing_state_array(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        del f["state/vel"]
    _refused(p, r"bad\.h5' is damaged: it lacks '/state/vel'")


def test_missing_group_and_config_key(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        del f["host"]
    _refused(p, r"is damaged: it lacks '/host'")
    p = _copy(saved, tmp_path, "cfg.h5")
    with h5py.File(p, "a") as f:
        cfg = json.loads(f.attrs["config"])
        del cfg["n"]
        f.attrs["config"] = json.dumps(cfg)
    _refused(p, r"cfg\.h5' is damaged: its config lacks 'n'")


def test_corrupt_config_json(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        f.attrs["config"] = f.attrs["config"][:-7]
    _refused(p, r"is damaged: its config is not valid JSON")


def test_too_short_state_array(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        pos = f["state/pos"][()]
        del f["state/pos"]
        f["state/pos"] = pos[:-1]
    _refused(p, r"is damaged: '/state/pos' has shape \(29, 2\), expected \(30, 2\) for its "
                r"30 particles")


def test_nan_position(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        pos = f["state/pos"][()]
        pos[7, 1] = np.nan
        f["state/pos"][...] = pos
    _refused(p, r"is damaged: '/state/pos' holds nan at \[7, 1\] \(not finite, particle 7\)")


def test_fix_outside_the_particles(saved, tmp_path):
    p = _copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        f["fixes/0000/ids"][...] = [30]
    _refused(p, r"is damaged: a prescribed velocity names particles \[30\] outside \[0, 30\)")
