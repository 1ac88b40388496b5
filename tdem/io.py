"""Output: monitors (histories), VTU snapshots and series, HDF5, plots."""
import numpy as np

from .errors import InputError


class Monitor:
    """History of ``fn(sim)`` recorded every ``every`` steps."""

    def __init__(self, name, fn, every=100, start=0):
        if not callable(fn):
            raise InputError(f"fn must be a function of the simulation, got {fn!r}")
        if int(every) != every or every < 1:
            raise InputError(f"every must be a whole number of steps >= 1, got {every!r}")
        self.name = str(name)
        self.fn = fn
        self.every = int(every)
        self.next_step = int(start) + self.every
        self.steps, self.times, self.values = [], [], []

    def record(self, sim):
        self.steps.append(sim.steps)
        self.times.append(sim.time)
        self.values.append(np.asarray(self.fn(sim), dtype=float))
        self.next_step = sim.steps + self.every

    def truncate(self, step):
        """Forget records after ``step`` (the run was rewound to it)."""
        while self.steps and self.steps[-1] > step:
            self.steps.pop()
            self.times.pop()
            self.values.pop()
        self.next_step = (self.steps[-1] if self.steps else step) + self.every
        if self.next_step <= step:
            self.next_step = step + 1

    def arrays(self):
        return np.array(self.times), (np.array(self.values) if self.values else np.zeros(0))
