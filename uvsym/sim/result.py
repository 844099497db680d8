"""SimResult: named, labelled, unit-carrying arrays of one simulation, with file I/O and plots.

Formats (chosen by suffix): ``.npz`` (numpy), ``.csv`` (one column per entry, header
``signal:label [unit]``, metadata as a ``#`` comment line), ``.mat`` (MATLAB, via scipy.io;
signal names with ``/`` are stored with ``__``).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.io

from uvsym.errors import SimulationError, UnknownNameError
from uvsym.paths import output_folder

__all__ = ["Signal", "SimResult"]

FORMATS = (".npz", ".csv", ".mat")


@dataclass(frozen=True)
class Signal:
    """values: (N, k) array; labels and units: k entries each."""

    values: np.ndarray
    labels: tuple[str, ...]
    units: tuple[str, ...]

    def __getitem__(self, label: str) -> np.ndarray:
        """The (N,) column of one entry, by label."""
        if label not in self.labels:
            raise UnknownNameError(f"no entry {label!r}; entries: {', '.join(self.labels)}")
        return self.values[:, self.labels.index(label)]


@dataclass(frozen=True)
class SimResult:
    """t: (N,) s; signals: name -> Signal (x, y, u_desired, u_command, u_expected, u_actual,
    fault_actuator, fault_sensor, tau_desired, reference, f_hat/<observer>; see ``simulate``);
    meta: JSON-friendly description of the run."""

    t: np.ndarray
    signals: dict[str, Signal]
    meta: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> Signal:
        if name not in self.signals:
            raise UnknownNameError(f"no signal {name!r}; signals: {', '.join(self.signals)}")
        return self.signals[name]

    def save(self, path) -> Path:
        """Write to ``path`` (its folder is made if missing); the suffix (.npz, .csv or .mat) picks the format."""
        path = Path(path)
        suffix = _suffix(path)
        output_folder(path.parent, "the result", SimulationError).mkdir(parents=True, exist_ok=True)
        if suffix == ".npz":
            arrays = {"t": self.t, "meta": np.array(json.dumps(self.meta))}
            for name, sig in self.signals.items():
                arrays[f"{name}:values"] = sig.values
                arrays[f"{name}:labels"] = np.array(sig.labels)
                arrays[f"{name}:units"] = np.array(sig.units)
            with path.open("wb") as handle:
                np.savez_compressed(handle, **arrays)
        elif suffix == ".csv":
            header = ["t [s]"] + [f"{name}:{lab} [{unit}]" for name, sig in self.signals.items()
                                  for lab, unit in zip(sig.labels, sig.units)]
            table = np.column_stack([self.t] + [sig.values for sig in self.signals.values()])
            with path.open("w", newline="") as handle:
                handle.write("# " + json.dumps(self.meta) + "\n")
                writer = csv.writer(handle)
                writer.writerow(header)
                writer.writerows([[repr(float(v)) for v in row] for row in table])
        else:
            content = {"t": self.t, "meta": json.dumps(self.meta),
                       "signals": np.array(list(self.signals), dtype=object)}
            for name, sig in self.signals.items():
                key = _mat_key(name)
                content[key] = sig.values
                content[key + "_labels"] = np.array(sig.labels, dtype=object)
                content[key + "_units"] = np.array(sig.units, dtype=object)
            scipy.io.savemat(path, content, do_compression=True)
        return path

    @classmethod
    def load(cls, path) -> SimResult:
        """Read a file written by :meth:`save`."""
        path = Path(path)
        suffix = _suffix(path)
        if not path.exists():
            raise SimulationError(f"no such result file: {path}")
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                names = [key[:-len(":values")] for key in data.files if key.endswith(":values")]
                signals = {name: Signal(data[f"{name}:values"], tuple(data[f"{name}:labels"].tolist()),
                                        tuple(data[f"{name}:units"].tolist())) for name in names}
                return cls(data["t"], signals, json.loads(str(data["meta"])))
        if suffix == ".csv":
            with path.open(newline="") as handle:
                meta = json.loads(handle.readline()[2:])
                rows = list(csv.reader(handle))
            header, table = rows[0], np.array(rows[1:], dtype=float).reshape(-1, len(rows[0]))
            columns: dict[str, list] = {}
            for index, column in enumerate(header[1:], 1):
                name_label, unit = column.rsplit(" [", 1)
                name, label = name_label.rsplit(":", 1)
                columns.setdefault(name, []).append((index, label, unit[:-1]))
            signals = {name: Signal(table[:, [c[0] for c in cols]], tuple(c[1] for c in cols),
                                    tuple(c[2] for c in cols)) for name, cols in columns.items()}
            return cls(table[:, 0], signals, meta)
        data = scipy.io.loadmat(path, simplify_cells=True)
        names = [data["signals"]] if isinstance(data["signals"], str) else list(data["signals"])
        signals = {}
        for name in names:
            key = _mat_key(name)
            values = np.atleast_2d(data[key])
            labels, units = np.atleast_1d(data[key + "_labels"]), np.atleast_1d(data[key + "_units"])
            signals[name] = Signal(values.reshape(-1, len(labels)), tuple(map(str, labels)), tuple(map(str, units)))
        return cls(np.atleast_1d(data["t"]).astype(float), signals, json.loads(data["meta"]))

    def plot(self, path=None, names: tuple[str, ...] | None = None):
        """Quick-look figure: one panel per signal and unit (angles in degrees); saved if ``path``.

        Default signals: states, commands and fault estimates of a scenario run; states, inputs
        and every block's published signals of a wired loop."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if not names and "u_command" in self.signals:  # the marine scenario loop
            names = tuple(n for n in ("x", "u_command", "u_actual") if n in self.signals) + tuple(
                n for n in self.signals if n.startswith("f_hat/"))
        elif not names:  # a wired loop: states, inputs and every block's signals
            names = tuple(n for n in self.signals if n not in ("y", "fault_sensor", "fault_actuator", "substitution"))
        panels = []
        for name in names:
            sig = self[name]
            groups: dict[str, list] = {}
            for label, unit, column in zip(sig.labels, sig.units, sig.values.T):
                scale, shown = (180.0 / np.pi, unit.replace("rad", "deg")) if "rad" in unit else (1.0, unit)
                groups.setdefault(shown, []).append((label, scale * column))
            panels += [(f"{name} ({unit})", lines) for unit, lines in groups.items()]
        fig, axes = plt.subplots(len(panels), 1, figsize=(9, 1.9 * len(panels)), sharex=True, squeeze=False)
        for ax, (title, lines) in zip(axes[:, 0], panels):
            for label, column in lines:
                ax.plot(self.t, column, label=label, lw=1)
            ax.set_title(title, fontsize=9, loc="left")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, ncol=min(len(lines), 6), loc="upper right")
        axes[-1, 0].set_xlabel("t (s)")
        fig.tight_layout()
        if path is not None:
            from uvsym.report.figures import save_svg

            path = Path(path)
            if path.suffix == ".svg":
                save_svg(fig, path)
            else:
                fig.savefig(path, dpi=110)
                plt.close(fig)
        return fig


def _suffix(path: Path) -> str:
    if path.suffix not in FORMATS:
        raise SimulationError(f"unknown result format {path.suffix!r} for {path}; use one of {', '.join(FORMATS)}")
    return path.suffix


def _mat_key(name: str) -> str:
    return name.replace("/", "__")
