"""The progress report: counts and the time left, as a bar on a terminal, as lines in a log."""

import io

from uvsym.progress import ProgressBar


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_log_gets_lines_with_counts_and_the_time_left():
    stream = io.StringIO()
    bar = ProgressBar("campaign", stream=stream, total=176, unit="runs", interval_s=0.0)
    bar(0.25)
    bar(1.0)
    first, last = stream.getvalue().splitlines()
    assert first.startswith("campaign:  44/176 runs (25%)") and "ETA" in first
    assert last.startswith("campaign:  176/176 runs (100%)") and "ETA" not in last


def test_a_short_step_prints_nothing_to_a_log():
    stream = io.StringIO()
    bar = ProgressBar("step", stream=stream, total=3, interval_s=60.0)
    for k in range(1, 4):
        bar(k / 3)
    assert stream.getvalue() == ""


def test_a_terminal_bar_is_redrawn_in_place_and_ends_its_line_when_done():
    stream = Terminal()
    bar = ProgressBar("verify", stream=stream, total=4, unit="claims")
    bar(0.5)
    bar(1.0)
    bar.close()  # already ended at 100 %: no empty line
    text = stream.getvalue()
    assert text.count("\r") == 2 and "2/4 claims" in text and "4/4 claims" in text
    assert text.endswith("\n") and not text.endswith("\n\n")


def test_run_campaign_tells_the_bar_how_many_runs_it_runs(tmp_path):
    from uvsym.campaign import load_campaign, run_campaign

    source = tmp_path / "c.toml"
    source.write_text('name = "tiny"\n[executor]\nkind = "local"\nworkers = 1\nchunk_size = 1\n'
                      '[simulation]\ncompiled = false\n[[case]]\nname = "a"\nscenario = "docking_faults"\n'
                      'set = { duration = 1.0 }\n[case.grid]\n"seed" = [1, 2, 3]\n')
    stream = io.StringIO()
    bar = ProgressBar("tiny", stream=stream, unit="runs", interval_s=0.0)
    run_campaign(load_campaign(source), tmp_path / "out", executor="local", workers=1, progress=bar)
    assert bar.total == 3
    assert stream.getvalue().splitlines()[-1].startswith("tiny:  3/3 runs (100%)")
