"""SimResult files round-trip every valid result exactly, in every format (property test), and
malformed files give typed errors that name the path."""

import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from uvsym.errors import FileFormatError, PathError, SimulationError
from uvsym.sim.result import COMPRESSED, FORMATS, Signal, SimResult

# every string a result accepts: no control characters, no lone surrogates (UTF-8 encodable)
TEXT = st.text(st.characters(blacklist_categories=("Cc", "Cs")), max_size=12)
FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)


@st.composite
def results(draw):
    n = draw(st.integers(0, 4))
    names = draw(st.lists(TEXT.filter(bool), max_size=4, unique=True))
    signals = {}
    for name in names:
        k = draw(st.integers(0, 3))
        signals[name] = Signal(draw(arrays(np.float64, (n, k), elements=FLOATS)),
                               tuple(draw(st.lists(TEXT, min_size=k, max_size=k))),
                               tuple(draw(st.lists(TEXT, min_size=k, max_size=k))))
    meta = draw(st.dictionaries(TEXT, st.one_of(st.integers(-10**6, 10**6), TEXT,
                                                st.floats(allow_nan=False, allow_infinity=False)), max_size=3))
    times = np.sort(draw(arrays(np.float64, (n,), elements=st.floats(allow_nan=False, allow_infinity=False,
                                                                     width=64))))  # finite, never decreasing
    return SimResult(times, signals, meta)


def _assert_same(loaded: SimResult, original: SimResult) -> None:
    np.testing.assert_array_equal(loaded.t, original.t)  # NaN equals NaN here, and -0.0 == 0.0
    assert list(loaded.signals) == list(original.signals)
    for name, signal in original.signals.items():
        assert loaded[name].values.shape == signal.values.shape, name
        np.testing.assert_array_equal(loaded[name].values, signal.values, err_msg=name)
        numbers = ~np.isnan(signal.values)  # -0.0 keeps its sign (a NaN's sign is no datum)
        assert np.array_equal(np.signbit(loaded[name].values[numbers]), np.signbit(signal.values[numbers])), name
        assert (loaded[name].labels, loaded[name].units) == (signal.labels, signal.units)
    assert loaded.meta == original.meta


@pytest.mark.parametrize("suffix", FORMATS)
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(result=results())
def test_every_valid_result_round_trips_exactly(tmp_path, suffix, result):
    path = result.save(tmp_path / f"r{suffix}", overwrite=True)
    _assert_same(SimResult.load(path), result)


@pytest.mark.parametrize("suffix", COMPRESSED)
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(result=results())
def test_every_valid_result_round_trips_exactly_compressed_too(tmp_path, suffix, result):
    path = result.save(tmp_path / f"r{suffix}", overwrite=True, compress=True)
    _assert_same(SimResult.load(path), result)


def test_results_are_compressed_only_when_asked_and_only_in_the_formats_that_compress(tmp_path):
    n = 20_000  # a long, regular run: what compression shrinks
    result = SimResult(np.arange(n) * 0.01, {"x": Signal(np.zeros((n, 3)), ("a", "b", "c"), ("m", "m", "m"))})
    plain, packed = result.save(tmp_path / "plain.npz"), result.save(tmp_path / "packed.npz", compress=True)
    for path, kind in ((plain, zipfile.ZIP_STORED), (packed, zipfile.ZIP_DEFLATED)):
        with zipfile.ZipFile(path) as archive:
            assert {entry.compress_type for entry in archive.infolist()} == {kind}, path.name
        _assert_same(SimResult.load(path), result)
    plain, packed = result.save(tmp_path / "plain.mat"), result.save(tmp_path / "packed.mat", compress=True)
    assert packed.stat().st_size < plain.stat().st_size / 10  # 640 kB of zeros
    _assert_same(SimResult.load(packed), result)
    with pytest.raises(SimulationError, match=r"cannot compress .*run.csv: only .npz and .mat files are compressed"):
        result.save(tmp_path / "run.csv", compress=True)
    assert not (tmp_path / "run.csv").exists()


@pytest.mark.parametrize("suffix", FORMATS)
def test_the_cases_that_used_to_lose_data(tmp_path, suffix):
    """A label with ':', a 0-column signal, 'a/b' beside 'a__b', an empty label, a name like '_x'."""
    n = 3
    result = SimResult(np.arange(n) * 0.5, {
        "a/b": Signal(np.ones((n, 1)), ("x:y",), ("m [abs]",)),
        "a__b": Signal(2 * np.ones((n, 2)), ("", "q"), ("", "rad")),
        "_x": Signal(np.zeros((n, 0)), (), ()),
        "t": Signal(-np.ones((n, 1)), ("meta",), ("s",)),
    }, {"note": "layout"})
    _assert_same(SimResult.load(result.save(tmp_path / f"r{suffix}")), result)


def test_names_and_shapes_that_no_format_can_hold_are_refused(tmp_path):
    with pytest.raises(SimulationError, match="a signal name must be a non-empty string"):
        SimResult(np.zeros(2), {"": Signal(np.zeros((2, 1)), ("a",), ("m",))})
    with pytest.raises(SimulationError, match="label 0 must be a string without control characters"):
        Signal(np.zeros((2, 1)), ("a\nb",), ("m",))
    with pytest.raises(SimulationError, match=r"values \(2, 2\), 1 labels, 1 units"):
        Signal(np.zeros((2, 2)), ("a",), ("m",))
    with pytest.raises(SimulationError, match="one row per time"):
        SimResult(np.zeros(3), {"x": Signal(np.zeros((2, 1)), ("a",), ("m",))})
    with pytest.raises(SimulationError, match="meta must be JSON-friendly"):
        SimResult(np.zeros(1), {}, {"when": object()}).save(tmp_path / "r.npz")
    assert not (tmp_path / "r.npz").exists()


def test_existing_files_are_kept_unless_overwrite(tmp_path):
    result = SimResult(np.array([0.0, 1.0]), {"x": Signal(np.array([[1.0], [2.0]]), ("a",), ("m",))})
    path = tmp_path / "run.npz"
    path.write_text("someone's data")
    with pytest.raises(PathError, match="run.npz exists; refusing to overwrite"):
        result.save(path)
    assert path.read_text() == "someone's data"
    result.save(path, overwrite=True)
    assert SimResult.load(path)["x"]["a"].tolist() == [1.0, 2.0]
    with pytest.raises(PathError, match="is a file, not a folder"):
        result.save(path / "inside.csv")
    with pytest.raises(PathError, match="no such result file"):
        SimResult.load(tmp_path / "missing.csv")


@pytest.mark.parametrize("name, content", [
    ("bad.csv", "t [s]\n0.0\n"),                                   # no meta/layout comment
    ("json.csv", "# {not json\n"),
    ("cols.csv", '# {"meta": {}, "layout": [{"name": "x", "labels": ["a"], "units": ["m"]}]}\nt [s]\n0.0\n'),
    ("text.csv", '# {"meta": {}, "layout": []}\nt [s]\nzero\n'),
    ("bad.npz", "not a zip"),
    ("bad.mat", "not a MATLAB file"),
])
def test_malformed_files_give_typed_errors_naming_the_path(tmp_path, name, content):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(FileFormatError, match=f"{name} is not a result file uvsym wrote"):
        SimResult.load(path)


def test_an_npz_without_its_layout_is_a_format_error(tmp_path):
    path = tmp_path / "plain.npz"
    np.savez(path, t=np.zeros(2))
    assert zipfile.is_zipfile(path)
    with pytest.raises(FileFormatError, match="KeyError"):
        SimResult.load(path)
