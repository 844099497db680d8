"""SimResult: named, labelled, unit-carrying arrays of one simulation, with file I/O and plots.

Formats (chosen by suffix), each round-tripping every valid result exactly: ``.npz`` (numpy;
``NAME:values`` arrays), ``.csv`` (one column per entry, header ``signal:label [unit]``),
``.mat`` (MATLAB via scipy.io; each signal under a valid MATLAB variable name). Every file also
holds ``meta`` and the ``layout`` (signal names, labels and units in order) as JSON (in the CSV,
on its first line after ``#``), which is what loading reads.
"""

from __future__ import annotations

import csv
import json
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from uvsym.errors import FileFormatError, PathError, SimulationError, UnknownNameError
from uvsym.paths import output_file

__all__ = ["Signal", "SimResult", "COMPRESSED", "FORMATS", "FIGURE_FORMATS"]

FORMATS = (".npz", ".csv", ".mat")
COMPRESSED = (".npz", ".mat")  # the formats SimResult.save(..., compress=True) deflates
FIGURE_FORMATS = (".svg", ".png", ".pdf")
_CONTROL = re.compile(r"[\x00-\x1f\x7f\ud800-\udfff]")  # control characters, lone surrogates


def _text(value, what: str, allow_empty: bool = True) -> str:
    """``value`` if it is a string every format can hold (no control characters or lone surrogates);
    SimulationError naming ``what``."""
    if not isinstance(value, str) or _CONTROL.search(value) or (not allow_empty and not value):
        raise SimulationError(f"{what} must be a{'' if allow_empty else ' non-empty'} string without control "
                              f"characters, got {value!r}")
    return value


@dataclass(frozen=True)
class Signal:
    """values: (N, k) array; labels and units: k strings each (no control characters)."""

    values: np.ndarray
    labels: tuple[str, ...]
    units: tuple[str, ...]

    def __post_init__(self):
        values = np.asarray(self.values, dtype=float)
        labels, units = tuple(self.labels), tuple(self.units)
        if values.ndim != 2 or values.shape[1] != len(labels) or len(units) != len(labels):
            raise SimulationError(f"a signal needs (N, k) values with k labels and k units, got values "
                                  f"{values.shape}, {len(labels)} labels, {len(units)} units")
        for i, (label, unit) in enumerate(zip(labels, units)):
            _text(label, f"label {i}")
            _text(unit, f"unit of {label!r}")
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "units", units)

    def __getitem__(self, label: str) -> np.ndarray:
        """The (N,) column of one entry, by label."""
        if label not in self.labels:
            raise UnknownNameError(f"no entry {label!r}; entries: {', '.join(self.labels)}")
        return self.values[:, self.labels.index(label)]


@dataclass(frozen=True)
class SimResult:
    """t: (N,) s; signals: name -> Signal (x, y, u_desired, u_command, u_expected, u_actual,
    fault_actuator, fault_sensor, tau_desired, reference, f_hat/<observer>; see ``simulate``);
    meta: description of the run, JSON-friendly to be saved (``events``: the diagnosis's decision
    log, see :attr:`events`). Names are non-empty strings without
    control characters; every signal has one row per time."""

    t: np.ndarray
    signals: dict[str, Signal]
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1:
            raise SimulationError(f"t must be a 1-D array of times (s), got shape {t.shape}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
            bad = int(np.flatnonzero(~np.isfinite(t))[0]) if not np.all(np.isfinite(t)) else \
                int(np.flatnonzero(np.diff(t) < 0)[0]) + 1
            raise SimulationError(f"t must be finite and never decreasing (s); t[{bad}] = {float(t[bad])!r} after "
                                  f"{float(t[bad - 1])!r}" if bad else f"t must be finite (s); t[0] = {float(t[0])!r}")
        for name, sig in self.signals.items():
            _text(name, "a signal name", allow_empty=False)
            if not isinstance(sig, Signal) or sig.values.shape[0] != t.size:
                raise SimulationError(f"signal {name!r} must be a Signal with one row per time ({t.size})")
        object.__setattr__(self, "t", t)

    @property
    def events(self) -> list[dict]:
        """The diagnosis's decision log (:mod:`uvsym.diagnosis.events`), empty for a run without one."""
        return list(self.meta.get("events", []))

    def __getitem__(self, name: str) -> Signal:
        if name not in self.signals:
            raise UnknownNameError(f"no signal {name!r}; signals: {', '.join(self.signals)}")
        return self.signals[name]

    @staticmethod
    def check_path(path, overwrite: bool = False, compress: bool = False) -> Path:
        """``path`` checked before a run writes it: a known suffix, and one that compresses (.npz, .mat) if
        ``compress`` (SimulationError), its folder made if missing, no existing file unless ``overwrite``
        (PathError)."""
        path = Path(path)
        if _suffix(path) not in COMPRESSED and compress:
            raise SimulationError(f"cannot compress {path}: only {' and '.join(COMPRESSED)} files are compressed")
        return output_file(path, "the result", overwrite)

    @staticmethod
    def check_plot_path(path, overwrite: bool = False) -> Path:
        """``path`` checked before a run plots to it: a figure suffix (.svg, .png or .pdf), not a
        folder, its folder made if missing, no existing file unless ``overwrite`` (PathError)."""
        path = Path(path)
        if path.suffix not in FIGURE_FORMATS and not path.is_dir():
            raise PathError(f"cannot write the figure to {path}: give it one of the suffixes "
                            f"{', '.join(FIGURE_FORMATS)}")
        return output_file(path, "the figure", overwrite)

    def save(self, path, overwrite: bool = False, compress: bool = False) -> Path:
        """Write to ``path`` (its folder is made if missing); the suffix (.npz, .csv or .mat) picks the
        format. An existing file is kept (PathError) unless ``overwrite``. ``compress``: deflate the arrays of
        a .npz or .mat file (about half the size, for some twenty times the writing time of a long run);
        :meth:`load` reads either."""
        path = self.check_path(path, overwrite, compress)
        try:
            json.dumps(self.meta)
        except (TypeError, ValueError) as exc:
            raise SimulationError(f"cannot save {path}: meta must be JSON-friendly ({exc})") from None
        layout = [{"name": n, "labels": list(s.labels), "units": list(s.units)} for n, s in self.signals.items()]
        try:
            _WRITERS[path.suffix](self, path, layout, compress)
        except OSError as exc:
            raise PathError(f"cannot write the result to {path}: {exc.strerror or exc}") from None
        return path

    @classmethod
    def load(cls, path) -> SimResult:
        """Read a file written by :meth:`save`; PathError when it cannot be read, FileFormatError
        when its content is not a result."""
        path = Path(path)
        suffix = _suffix(path)
        if not path.is_file():
            raise PathError(f"no such result file: {path}")
        try:
            t, arrays, meta, layout = _READERS[suffix](path)
            signals = {}
            for i, item in enumerate(layout):
                values = np.asarray(arrays[i], dtype=float).reshape(t.size, len(item["labels"]))
                signals[item["name"]] = Signal(values, tuple(item["labels"]), tuple(item["units"]))
            return cls(t, signals, meta)
        except OSError as exc:
            raise PathError(f"cannot read {path}: {exc.strerror or exc}") from None
        except (ValueError, KeyError, IndexError, TypeError, AttributeError, zipfile.BadZipFile,
                NotImplementedError, SimulationError) as exc:
            raise FileFormatError(f"{path} is not a result file uvsym wrote ({type(exc).__name__}: {exc})") from None

    def plot(self, path=None, names: tuple[str, ...] | None = None, overwrite: bool = False):
        """Quick-look figure: one panel per signal and unit (angles in degrees); saved if ``path``
        (checked by :meth:`check_plot_path`: an existing file is kept unless ``overwrite``).

        Default signals: states, commands and fault estimates of a scenario run; states, inputs
        and every block's published signals of a wired loop (a command drawn once, as the plant
        input, where no actuator fault makes the two differ). Every panel marks the faults' onsets
        (dashed vermillion; whole-run sensor noise is not a fault) and the detectors' alarms (detected,
        isolated or identified: dotted black), from the result's meta and decision log."""
        if path is not None:
            path = self.check_plot_path(path, overwrite)
        from uvsym.report.figures import figure_style, plt, save_svg

        with figure_style():
            return self._plot(plt, save_svg, path, names)

    def _plot(self, plt, save_svg, path, names):
        """The figure of :meth:`plot`, drawn in uvsym's style."""
        from uvsym.report.style import finish

        if not names and "u_command" in self.signals:  # the marine scenario loop
            names = tuple(n for n in ("x", "u_command", "u_actual") if n in self.signals) + tuple(
                n for n in self.signals if n.startswith("f_hat/"))
        elif not names:  # a wired loop: states, inputs and every block's signals
            names = tuple(n for n in self.signals if n not in ("y", "fault_sensor", "fault_actuator", "substitution"))
        inputs = dict(zip(self["u"].labels, self["u"].values.T)) if "u" in self.signals else {}
        panels = []
        for name in names:
            sig = self[name]
            groups: dict[str, list] = {}
            for label, unit, column in zip(sig.labels, sig.units, sig.values.T):
                if name != "u" and label in inputs and np.array_equal(column, inputs[label]):
                    continue  # a command the plant input shows as it is (no actuator fault on it)
                scale, shown = (180.0 / np.pi, unit.replace("rad", "deg")) if "rad" in unit else (1.0, unit)
                groups.setdefault(shown, []).append((label, scale * column))
            panels += [(name, unit, lines) for unit, lines in groups.items()]
        fig, axes = plt.subplots(len(panels), 1, figsize=(9, 1.9 * len(panels)), sharex=True, squeeze=False)
        from uvsym.diagnosis.events import ALARMS  # here: the diagnosis package builds on uvsym.sim

        onsets = sorted({f["onset_s"] for kind in ("actuator_faults", "sensor_faults")
                         for f in self.meta.get(kind, ()) if not f.get("kind", "").endswith("noise")})
        alarms = sorted({e["t"] for e in (self.meta.get("events") or ()) if e["event"] in ALARMS})
        for ax, (title, unit, lines) in zip(axes[:, 0], panels):
            for label, column in lines:
                ax.plot(self.t, column, label=label, lw=1)
            for times, style, what in ((onsets, dict(color="C1", ls="--"), "fault onset"),
                                       (alarms, dict(color="black", ls=":"), "alarm")):
                for i, when in enumerate(times):
                    ax.axvline(when, lw=0.8, label=what if i == 0 and ax is axes[0, 0] else None, **style)
            ax.set_ylabel(f"{title} ({unit or '-'})")
            ax.legend()
        axes[-1, 0].set_xlabel("t (s)")
        finish(fig)
        if path is not None:
            try:
                if path.suffix == ".svg":
                    save_svg(fig, path)
                else:
                    fig.savefig(path)
                    plt.close(fig)
            except OSError as exc:
                raise PathError(f"cannot write the figure to {path}: {exc.strerror or exc}") from None
        return fig


def _suffix(path: Path) -> str:
    if path.suffix not in FORMATS:
        raise SimulationError(f"unknown result format {path.suffix!r} for {path}; use one of {', '.join(FORMATS)}")
    return path.suffix


def _write_npz(result: SimResult, path: Path, layout: list, compress: bool) -> None:
    arrays = {"t": result.t, "meta": np.array(json.dumps(result.meta)), "layout": np.array(json.dumps(layout))}
    arrays |= {f"{name}:values": sig.values for name, sig in result.signals.items()}
    with path.open("wb") as handle:
        (np.savez_compressed if compress else np.savez)(handle, **arrays)


def _read_npz(path: Path):
    with np.load(path, allow_pickle=False) as data:
        layout = json.loads(str(data["layout"]))
        return (data["t"], [data[f"{item['name']}:values"] for item in layout], json.loads(str(data["meta"])),
                layout)


def _write_csv(result: SimResult, path: Path, layout: list, compress: bool) -> None:  # text: never compressed
    header = ["t [s]"] + [f"{name}:{lab} [{unit}]" for name, sig in result.signals.items()
                          for lab, unit in zip(sig.labels, sig.units)]
    table = np.column_stack([result.t] + [sig.values for sig in result.signals.values()])
    with path.open("w", newline="", encoding="utf-8") as handle:
        handle.write("# " + json.dumps({"meta": result.meta, "layout": layout}) + "\n")
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows([[repr(float(v)) for v in row] for row in table])


def _read_csv(path: Path):
    with path.open(newline="", encoding="utf-8") as handle:
        first = handle.readline()
        if not first.startswith("# "):
            raise ValueError("the first line is not the '# {meta, layout}' comment")
        head = json.loads(first[2:])
        rows = list(csv.reader(handle))
    layout, widths = head["layout"], [len(item["labels"]) for item in head["layout"]]
    if not rows or len(rows[0]) != 1 + sum(widths):
        raise ValueError(f"the header has {len(rows[0]) if rows else 0} columns, the layout {1 + sum(widths)}")
    table = np.array(rows[1:], dtype=float).reshape(len(rows) - 1, 1 + sum(widths))
    edges = np.cumsum([1] + widths)
    return table[:, 0], [table[:, a:b] for a, b in zip(edges[:-1], edges[1:])], head["meta"], layout


def _write_mat(result: SimResult, path: Path, layout: list, compress: bool) -> None:
    keys = _mat_keys(list(result.signals))
    layout = [{**item, "key": key} for item, key in zip(layout, keys)]
    content = {"t": result.t, "meta": json.dumps(result.meta), "layout": json.dumps(layout)}
    content |= {key: sig.values for key, sig in zip(keys, result.signals.values())}
    import scipy.io  # here: importing it costs every uvsym command about 0.1 s

    scipy.io.savemat(path, content, do_compression=compress)


def _read_mat(path: Path):
    import scipy.io

    try:
        data = scipy.io.loadmat(path, simplify_cells=True)
    except scipy.io.matlab.MatReadError as exc:  # not a MATLAB file: the caller's format error
        raise ValueError(str(exc)) from None
    layout = json.loads(data["layout"])
    return (np.asarray(data["t"], dtype=float).reshape(-1), [data[item["key"]] for item in layout],
            json.loads(data["meta"]), layout)


def _mat_keys(names: list[str]) -> list[str]:
    """A distinct MATLAB variable name per signal (a letter, then letters, digits, _; <= 63 chars),
    readable where the name allows (``f_hat/bias`` -> ``f_hat_bias``), never t, meta or layout."""
    keys, taken = [], {"t", "meta", "layout"}
    for name in names:
        base = re.sub(r"[^A-Za-z0-9_]", "_", name)
        base = (base if base[:1].isalpha() else "s_" + base)[:56]
        key, count = base, 1
        while key in taken:
            count += 1
            key = f"{base}_{count}"
        taken.add(key)
        keys.append(key)
    return keys


_WRITERS = {".npz": _write_npz, ".csv": _write_csv, ".mat": _write_mat}
_READERS = {".npz": _read_npz, ".csv": _read_csv, ".mat": _read_mat}
