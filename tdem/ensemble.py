"""Ensembles: one function over many parameter sets, on a Dask cluster.

:func:`ensemble` calls ``fn(**p)`` for every parameter set ``p`` of ``params``, each
call a task of a ``dask.distributed`` cluster (a local one of this machine's cores,
or one of many machines given by its scheduler's address), and gathers what each
returns into one table, in the order of ``params``::

    res = tdem.ensemble(drop, {"height": [1.0, 2.0], "steps": [100, 200]}, out="runs")
    res.rows            # [{"height": 1.0, "steps": 100, "y": ..., "wall_s": ...,
                        #   "status": "ok", "error": ""}, ...]

- each worker is one process that runs one member at a time, with its own Taichi
  runtime: ``$TDEM_THREADS`` is set on each worker (the machine's cores shared among
  the workers on it) and, on a machine whose ``nvidia-smi`` lists GPUs,
  ``$CUDA_VISIBLE_DEVICES`` to one GPU per worker, before the worker's first
  simulation;
- a member that raises is a row with ``status="error"`` and the traceback in
  ``error``; the others go on, and a warning sums the failures up at the end;
- with ``out``, each member's result is kept in ``out/members/<key>.json`` as it
  ends (``key``: a hash of its parameters), and the table is written to
  ``out/results.csv`` and ``out/results.h5``; run again with the same ``out``, the
  members found there (those that ended ``ok``) are read back, not run again;
- the numbers are those of ``fn(**p)`` called in this process, bit for bit: each
  member runs alone in its worker, and floats travel as their exact decimal text.

Dask is an optional extra (``pip install "tdem[sweep]"``), imported on first use.
"""
import csv
import hashlib
import io
import itertools
import json
import math
import numbers
import os
import shutil
import subprocess
import sys
import time
import traceback
import warnings
from pathlib import Path

from .errors import InputError

SWEEP_INSTALL = 'pip install "tdem[sweep]"'
#: the columns every row has after its parameters and outputs
STATUS_COLUMNS = ("wall_s", "status", "error")
PLUGIN_NAME = "tdem-ensemble-worker"


# ------------------------------------------------------------------ parameters
def grid(**axes):
    """The Cartesian product of the values of each keyword, as a list of dicts (the
    last keyword varies fastest): ``grid(a=[1, 2], b=[0.1, 0.2])`` is
    ``[{"a": 1, "b": 0.1}, {"a": 1, "b": 0.2}, {"a": 2, "b": 0.1}, {"a": 2, "b": 0.2}]``.
    A value that is not a list (or tuple, or array) is one value for every member."""
    names = list(axes)
    values = []
    for name in names:
        v = axes[name]
        if isinstance(v, (str, bytes, dict)) or not hasattr(v, "__iter__"):
            v = [v]
        v = list(v)
        if not v:
            raise InputError(f"grid: {name} has no values, got {axes[name]!r}")
        values.append(v)
    return [dict(zip(names, combo)) for combo in itertools.product(*values)]


def _plain(value, where):
    """``value`` as plain JSON types (numpy scalars and arrays to numbers and lists);
    InputError naming ``where`` for what JSON cannot hold."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "tolist") and callable(value.tolist):      # numpy arrays, scalars
        return _plain(value.tolist(), where)
    if isinstance(value, (list, tuple)):
        return [_plain(v, where) for v in value]
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise InputError(f"{where}: keys must be strings, got {k!r}")
            out[k] = _plain(v, f"{where}[{k!r}]")
        return out
    raise InputError(f"{where} must be numbers, strings, lists or dicts (JSON), got "
                     f"{value!r} of type {type(value).__name__}")


def members_of(params):
    """The list of parameter dicts of ``params``: a list (or tuple) of dicts, or a dict
    whose values are lists (their Cartesian product, :func:`grid`)."""
    if isinstance(params, dict):
        members = grid(**params)
    elif isinstance(params, (list, tuple)):
        members = list(params)
    else:
        raise InputError("params must be a list of dicts or a dict of lists (a grid), got "
                         f"{params!r} of type {type(params).__name__}")
    if not members:
        raise InputError(f"params has no members, got {params!r}")
    plain = []
    for k, p in enumerate(members):
        if not isinstance(p, dict):
            raise InputError(f"params[{k}] must be a dict of keyword arguments, got {p!r}")
        for name in p:
            if not isinstance(name, str) or not name.isidentifier():
                raise InputError(f"params[{k}]: {name!r} is not a keyword argument name")
            if name in STATUS_COLUMNS:
                raise InputError(f"params[{k}]: {name!r} is a column of the table "
                                 f"({', '.join(STATUS_COLUMNS)}); name it otherwise")
        plain.append(_plain(p, f"params[{k}]"))
    return plain


def member_key(p):
    """A stable hash of the parameters ``p`` (16 hex digits): the same in every
    process and on every machine, whatever the order of the keys."""
    text = json.dumps(_plain(p, "params"), sort_keys=True, separators=(",", ":"),
                      allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ------------------------------------------------------------------ one member
def run_member(fn, p):
    """Call ``fn(**p)`` here and return its record: ``params``, ``outputs`` (a dict:
    ``fn``'s dict, or ``{"result": value}`` for anything else), ``status`` ("ok" or
    "error"), ``error`` (the traceback text, "" when ok) and ``wall_s``."""
    t0 = time.perf_counter()
    try:
        value = fn(**p)
        outputs = value if isinstance(value, dict) else {"result": value}
        outputs = _plain(outputs, "the result of fn")
        status, error = "ok", ""
    except Exception:                                   # reported in the table
        outputs, status, error = {}, "error", traceback.format_exc()
    return {"key": member_key(p), "params": p, "outputs": outputs, "status": status,
            "error": error, "wall_s": time.perf_counter() - t0}


def row_of(record):
    """The table row of a member's record: its parameters, its outputs (an output of a
    parameter's name replaces it), then wall_s, status and error."""
    row = dict(record["params"])
    row.update({k: v for k, v in record["outputs"].items() if k not in STATUS_COLUMNS})
    row.update(wall_s=record["wall_s"], status=record["status"], error=record["error"])
    return row


# ------------------------------------------------------------------ workers
def _gpu_count():
    """GPUs that ``nvidia-smi -L`` lists (0 without it)."""
    exe = shutil.which("nvidia-smi")
    if exe is None:
        return 0
    try:
        out = subprocess.run([exe, "-L"], capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return 0
    if out.returncode != 0:
        return 0
    return sum(1 for line in out.stdout.splitlines() if line.startswith("GPU "))


def worker_environment(index, workers_here, cores=None, gpus=None, environ=None):
    """The variables a worker sets before its first simulation: ``TDEM_THREADS`` (the
    cores shared among the ``workers_here`` workers of its machine, at least 1) and,
    with GPUs, ``CUDA_VISIBLE_DEVICES`` (GPU ``index`` mod their number). Variables
    already set (``environ``) are kept."""
    environ = os.environ if environ is None else environ
    cores = (os.cpu_count() or 1) if cores is None else cores
    gpus = _gpu_count() if gpus is None else gpus
    env = {}
    if not environ.get("TDEM_THREADS"):
        env["TDEM_THREADS"] = str(max(1, int(cores) // max(1, int(workers_here))))
    if gpus > 0 and not environ.get("CUDA_VISIBLE_DEVICES"):
        env["CUDA_VISIBLE_DEVICES"] = str(int(index) % int(gpus))
    return env


def _dask():
    try:
        import distributed
    except ImportError as e:
        raise ImportError(f"tdem.ensemble runs on Dask (dask.distributed), which is not "
                          f"installed: {SWEEP_INSTALL} (or pip install "
                          f'"dask[distributed]") ({e})') from None
    return distributed


def _register(client, threads):
    from ._dask_worker import WorkerSetup
    plugin = WorkerSetup(threads)
    if hasattr(client, "register_plugin"):
        client.register_plugin(plugin, name=PLUGIN_NAME)
    else:                                               # older distributed
        client.register_worker_plugin(plugin, name=PLUGIN_NAME)


# ------------------------------------------------------------------ the table
class Results:
    """The rows of an ensemble, in the order of its ``params`` (``.rows``, a list of
    dicts; also ``len``, iteration, indexing), with ``.errors`` (the rows that
    raised), ``.columns`` and ``.to_csv(path)`` / ``.to_h5(path)``."""

    def __init__(self, rows):
        self.rows = rows

    def __len__(self):
        return len(self.rows)

    def __iter__(self):
        return iter(self.rows)

    def __getitem__(self, k):
        return self.rows[k]

    def __repr__(self):
        return (f"<tdem.ensemble results: {len(self.rows)} members, "
                f"{len(self.errors)} errors>")

    @property
    def errors(self):
        return [r for r in self.rows if r["status"] != "ok"]

    @property
    def columns(self):
        names = {}
        for r in self.rows:
            for k in r:
                if k not in STATUS_COLUMNS:
                    names[k] = None
        return list(names) + list(STATUS_COLUMNS)

    def column(self, name):
        """The values of column ``name`` (None where a row has none)."""
        return [r.get(name) for r in self.rows]

    def to_csv(self, path):
        """The table as CSV: one row per member; a value that is not a number or a
        string is its JSON text, a missing one an empty cell."""
        cols = self.columns
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        for r in self.rows:
            w.writerow([_cell(r.get(c)) for c in cols])
        _write_atomic(Path(path), buf.getvalue().encode())

    def to_h5(self, path):
        """The table as HDF5: a dataset per column at the root (the attribute
        ``columns`` lists them in order); numbers as float64 (NaN where missing) or
        int64, the rest as UTF-8 strings (JSON text for lists and dicts)."""
        import h5py
        import numpy as np
        path = Path(path)
        part = path.with_name(path.name + ".part")
        cols = self.columns
        with h5py.File(part, "w") as f:
            f.attrs["columns"] = json.dumps(cols)
            for c in cols:
                values = self.column(c)
                name = c.replace("/", "_")
                present = [v for v in values if v is not None]
                if present and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                   for v in present):
                    if len(present) == len(values) and all(isinstance(v, int) for v in values):
                        data = np.asarray(values, dtype=np.int64)
                    else:
                        data = np.asarray([math.nan if v is None else float(v)
                                           for v in values], dtype=np.float64)
                    f.create_dataset(name, data=data)
                else:
                    f.create_dataset(name, data=[_cell(v) for v in values],
                                     dtype=h5py.string_dtype("utf-8"))
        os.replace(part, path)


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (int, str)):
        return str(v)
    return json.dumps(v)


def _write_atomic(path, data):
    part = path.with_name(path.name + ".part")
    part.write_bytes(data)
    os.replace(part, path)


def _out_dir(out):
    try:
        path = Path(out)
    except TypeError:
        raise InputError(f"out must be a folder path, got {out!r}") from None
    try:
        (path / "members").mkdir(parents=True, exist_ok=True)
        probe = path / "members" / ".tdem-write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise InputError(f"out: cannot write to {str(out)!r} ({e.strerror or e})") from None
    return path


def _read_member(path):
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None                                     # half written: run it again
    if not isinstance(record, dict) or record.get("status") != "ok":
        return None
    return record


# ------------------------------------------------------------------ the ensemble
def _client_of(client, workers, threads):
    """(client, closers): the ``distributed.Client`` to use and what to close after."""
    distributed = _dask()
    if client is None:
        n = workers if workers is not None else (os.cpu_count() or 1)
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise InputError(f"workers must be a whole number >= 1, got {workers!r}")
        env = {"TDEM_THREADS": str(threads if threads is not None
                                   else max(1, (os.cpu_count() or 1) // n))}
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1,
                                           processes=True, dashboard_address=None,
                                           env=env)
        c = distributed.Client(cluster)
        return c, [c, cluster]
    if isinstance(client, str):
        try:
            c = distributed.Client(client, timeout="30s")
        except OSError as e:
            raise InputError(f"client: no Dask scheduler answers at {client!r} ({e})") from None
        return c, [c]
    if isinstance(client, distributed.Client):
        return client, []
    raise InputError("client must be a dask.distributed Client, a scheduler address "
                     f"('tcp://host:8786') or None, got {client!r}")


def ensemble(fn, params, client=None, out=None, *, workers=None, threads=None,
             progress=True, on_result=None):
    """Run ``fn(**p)`` for every ``p`` of ``params`` on a Dask cluster; returns
    :class:`Results` (``.rows`` in the order of ``params``).

    Parameters
    ----------
    fn
        A function of keyword arguments returning a dict of numbers (or strings,
        lists), or one value (a number, a path: the column ``result``); it runs on
        the workers, so it must be importable there (or picklable by value).
    params
        A list of dicts, or a dict of lists (their Cartesian product, :func:`grid`).
    client
        A ``distributed.Client``, a scheduler address (``"tcp://host:8786"``), or
        None: a ``LocalCluster`` of ``workers`` processes (default: this machine's
        cores), one thread each, closed at the end.
    out
        A folder: each member kept in ``out/members/<key>.json`` as it ends, the
        table in ``out/results.csv`` and ``out/results.h5``; members already there
        (``ok``) are read back and not run again. None: nothing written.
    workers
        Processes of the local cluster (``client=None`` only).
    threads
        Taichi CPU threads of each worker (default: ``$TDEM_THREADS`` where the
        worker has it, else its machine's cores over its workers).
    progress
        A progress bar on stderr (tqdm); False: none.
    on_result
        Called here as ``on_result(row)`` as each member ends (not for those read
        back).
    """
    if not callable(fn):
        raise InputError(f"fn must be callable (a function of the parameters), got {fn!r}")
    members = members_of(params)
    if client is not None and workers is not None:
        raise InputError(f"workers: only with client=None (a local cluster), got "
                         f"workers={workers!r} with client={client!r}")
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
            raise InputError(f"threads must be a whole number >= 1, got {threads!r}")
    if on_result is not None and not callable(on_result):
        raise InputError(f"on_result must be callable or None, got {on_result!r}")
    folder = _out_dir(out) if out is not None else None

    keys = [member_key(p) for p in members]
    records = {}
    if folder is not None:
        for key in dict.fromkeys(keys):
            r = _read_member(folder / "members" / f"{key}.json")
            if r is not None:
                records[key] = r
    todo = {}
    for key, p in zip(keys, members):
        if key not in records:
            todo.setdefault(key, p)

    if todo:
        _run(fn, todo, records, client, workers, threads, folder, progress, on_result,
             done_before=len(keys) - sum(1 for k in keys if k in todo))

    res = Results([row_of(records[k]) for k in keys])
    if folder is not None:
        res.to_csv(folder / "results.csv")
        res.to_h5(folder / "results.h5")
    failed = [k for k, r in enumerate(res.rows) if r["status"] != "ok"]
    if failed:
        text = res.rows[failed[0]]["error"].strip()
        last = text.splitlines()[-1] if text else ""
        p = members[failed[0]]
        warnings.warn(f"tdem.ensemble: {len(failed)} of {len(res)} members raised; the "
                      f"first, {p}: {last}" + (f" (tracebacks in {folder / 'results.csv'})"
                                               if folder is not None else ""),
                      RuntimeWarning, stacklevel=2)
    return res


def _run(fn, todo, records, client, workers, threads, folder, progress, on_result,
         done_before):
    distributed = _dask()
    from tqdm.auto import tqdm
    c, closers = _client_of(client, workers, threads)
    bar = tqdm(total=len(todo) + done_before, initial=done_before, file=sys.stderr,
               disable=not progress, desc="ensemble", unit="member", dynamic_ncols=True)
    futures = []
    try:
        _register(c, threads)
        futures = [c.submit(run_member, fn, p, pure=False, key=f"tdem-member-{key}-"
                            f"{os.urandom(4).hex()}") for key, p in todo.items()]
        member = {f.key: (key, p) for f, (key, p) in zip(futures, todo.items())}
        for f in distributed.as_completed(futures):
            try:
                record = f.result()
            except Exception as e:                      # the worker died, fn not loadable
                key, p = member[f.key]
                record = {"key": key, "params": p, "outputs": {}, "status": "error",
                          "error": "".join(traceback.format_exception_only(type(e), e)),
                          "wall_s": math.nan}
            records[record["key"]] = record
            if folder is not None:
                _write_atomic(folder / "members" / f"{record['key']}.json",
                              json.dumps(record, allow_nan=True).encode())
            bar.update(1)
            if record["status"] != "ok":
                bar.set_postfix_str(f"{sum(r['status'] != 'ok' for r in records.values())} "
                                    "errors")
            if on_result is not None:
                on_result(row_of(record))
            f.release()
    finally:
        bar.close()
        for f in futures:
            if not f.done():
                f.cancel()
        for x in closers:
            x.close()
