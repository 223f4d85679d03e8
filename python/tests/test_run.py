"""sg.run gives the CLI's events."""
import stereoguard as sg

from conftest import strip_timing


def test_version_is_a_string():
    assert isinstance(sg.version, str) and sg.version.count(".") == 2


def test_run_scenario_matches_cli_events(cli_head_on_events):
    events = list(sg.run(scenario="head-on"))
    assert len(events) == len(cli_head_on_events) > 100
    for ours, theirs in zip(events, cli_head_on_events):
        assert strip_timing(ours) == strip_timing(theirs), ours["frame"]
    assert any(e["signal"] for e in events)  # head-on collides: the scenario alarms


def test_run_with_workers_gives_the_same_events(cli_head_on_events):
    events = [strip_timing(e) for e in sg.run(scenario="head-on", workers=2, tiles=2)]
    assert events == [strip_timing(e) for e in cli_head_on_events]


def test_run_summary_after_the_last_event():
    stream = sg.run(scenario="head-on-fast")
    assert stream.summary is None
    frames = sum(1 for _ in stream)
    assert stream.summary["frames"] == frames


def test_run_config_dict_is_applied():
    # A smallest obstacle larger than the image: nothing can be dangerous.
    events = list(sg.run(scenario="head-on-fast", config={"signal": {"min_area_px": 10**7}}))
    assert events and not any(e["signal"] for e in events)


def test_run_abandoned_iterator_stops_the_run():
    stream = sg.run(scenario="head-on")
    first = next(stream)
    assert first["frame"] == 0
    del stream  # must not hang nor crash


def test_run_unknown_scenario_raises_error():
    try:
        sg.run(scenario="no-such-scenario")
    except sg.Error as e:
        assert isinstance(e, ValueError) and "no-such-scenario" in str(e)
    else:
        raise AssertionError("no exception")


def test_run_unknown_keyword_raises_type_error():
    try:
        sg.run(scenario="head-on", wrokers=2)
    except TypeError as e:
        assert "wrokers" in str(e)
    else:
        raise AssertionError("no exception")


def test_run_missing_config_file_raises_error(tmp_path):
    missing = tmp_path / "none.yaml"
    try:
        sg.run(scenario="head-on", config=str(missing))
    except sg.Error as e:
        assert str(missing) in str(e)
    else:
        raise AssertionError("no exception")
