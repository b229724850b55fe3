"""Careless inputs to the ``graspgait`` command line: one line, the right exit status.

Each case is something a user could type. Bad input exits 2 with exactly one line on
stderr that names the field or flag and the bad value; a valid question with no answer
(no gait) exits 1 with at most three lines; nothing ends in a traceback, and nothing is
written when the input is refused. Cases run in-process (``main(argv)``) to stay fast.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from graspgait_env.cli import main

# (argv, expected exit status, substrings the one-line message must contain)
BAD_INPUT: list[tuple[str, list[str]]] = [
    # map
    ("map nosuch --mu 0.7", ["object", "nosuch", "ellipse"]),
    ("map ellipse --mu -1", ["--mu", "-1"]),
    ("map ellipse --mu nan", ["--mu", "nan"]),
    ("map ellipse --mu abc", ["--mu", "abc"]),
    ("map ellipse --mu 0.7 --n 3", ["--n", "3"]),
    ("map ellipse --mu 0.7 --n 100000", ["--n", "100000", "7200"]),
    ("map ellipse --mu 0.7 --n 2.5", ["--n", "2.5"]),
    ("map ellipse --mu 0.7 --png {tmp}/map.txt", ["--png", ".txt", ".png"]),
    ("map ellipse --mu 0.7 --npy {tmp}/map.png", ["--npy", ".png", ".npy"]),
    ("map ellipse --mu 0.7 --png {tmp}/afile/x.png", ["--png", "afile", "not a folder"]),
    ("map ellipse --mu 0.7 --png {tmp}", ["--png"]),
    ("map ellipse --mu 0.7 --png ''", ["--png", "empty"]),
    ("map ellipse --mu 0.7 --theta inf", ["--theta", "inf"]),
    ("map ellipse --mu 0.7 --hand nosuch", ["hand", "nosuch", "thesis"]),
    ("map {tmp}/bad.yaml --mu 0.7", ["bad.yaml", "YAML"]),
    ("map {tmp}/empty.yaml --mu 0.7", ["empty.yaml", "empty"]),
    ("map {tmp}/unknown_key.yaml --mu 0.7", ["unknown_key.yaml", "colour"]),
    ("map {tmp}/nosuch.yaml --mu 0.7", ["nosuch.yaml", "not found"]),
    ("map ellipse", ["--mu"]),
    ("nosuchcommand", ["nosuchcommand"]),
    # plan
    ("plan ellipse --mu 0.7 --planner nosuch", ["--planner", "nosuch"]),
    ("plan ellipse --mu 0.7 --planner rule --start 50", ["--start", "50"]),
    ("plan ellipse --mu 0.7 --planner rule --start a,b", ["--start", "a,b"]),
    ("plan ellipse --mu 0.7 --planner rule --start 51,271", ["51", "grid"]),
    ("plan ellipse --mu 0.7 --planner rule --start 50,60", ["--start", "50,60", "finger 1"]),
    ("plan ellipse --mu 0.7 --planner rule --start 100,270", ["--start", "100"]),
    ("plan ellipse --mu 0.7 --planner rule --start 1000,2", ["1000", "force-closure"]),
    ("plan ellipse --mu 0.7 --planner rule --turn 0", ["--turn", "0"]),
    ("plan ellipse --mu 0.7 --planner rule --turn nan", ["--turn", "nan"]),
    ("plan ellipse --mu 0.7 --planner optimal --turn 1e9", ["--turn", "1e+09", "3600"]),
    ("plan ellipse --mu 0.7 --planner optimal --n 4000", ["--n", "4000", "720"]),
    ("plan ellipse --mu 0.7 --planner rule --vertex-clearance 95", ["--vertex-clearance", "95"]),
    ("plan ellipse --mu 0.7 --planner rule --json {tmp}/plan.txt", ["--json", ".txt", ".json"]),
    ("plan ellipse --mu 0.7 --planner rule --motion {tmp}/m.json", ["--motion", ".json"]),
    ("plan ellipse --mu 0.7 --planner rule --png {tmp}/g.xyz", ["--png", ".xyz"]),
    ("plan ellipse --mu 0.7 --planner rule --json {tmp}/afile/p.json", ["--json", "afile"]),
    # bench
    ("bench --mus abc", ["--mus", "abc"]),
    ("bench --mus 0.7,-1", ["--mu", "-1"]),
    ("bench --planners nosuch", ["--planner", "nosuch"]),
    ("bench --objects nosuch", ["object", "nosuch"]),
    ("bench --starts 0", ["--starts", "0"]),
    ("bench --objects circle --mus 0.7 --starts 1 --csv {tmp}/b.json", ["--csv", ".json"]),
    # simulate
    ("simulate {tmp}/nosuch.json", ["nosuch.json", "no such plan"]),
    ("simulate {tmp}/garbage.json", ["garbage.json", "JSON"]),
    ("simulate {tmp}/nonnum.json", ["steps[0].contacts.1", "abc"]),
    ("simulate {tmp}/mu_string.json", ["'mu'", "0.7"]),
    ("simulate {tmp}/no_steps.json", ["'steps'"]),
    ("simulate {tmp}/bad_op.json", ["steps[1].op", "jump"]),
    ("simulate {tmp}/bad_delta.json", ["steps[1].delta", "x"]),
    ("simulate {tmp}/one_contact.json", ["steps[0].contacts"]),
    ("simulate {tmp}/finger_9.json", ["steps[0].contacts", "9"]),
    ("simulate {tmp}/extra_key.json", ["'colour'", "unknown"]),
    ("simulate {tmp}/no_object.json", ["'object'", "missing"]),
    ("simulate {tmp}/bad_object.json", ["object", "nosuch"]),
    ("simulate {tmp}/good.json --perturb a,b", ["--perturb", "a,b"]),
    ("simulate {tmp}/good.json --perturb 0.05,0,0", ["--perturb", "0.05 m", "0.01 m"]),
    ("simulate {tmp}/good.json --perturb 0,0,30", ["--perturb", "30", "deg"]),
    ("simulate {tmp}/good.json --perturb 0,0,inf", ["--perturb", "inf"]),
    ("simulate {tmp}/good.json --video {tmp}/out.gif", ["--video", ".gif", ".mp4"]),
    ("simulate {tmp}/good.json --video {tmp}/afile/v.mp4", ["--video", "afile"]),
    ("simulate {tmp}/good.json --json {tmp}/r.txt", ["--json", ".txt"]),
    ("simulate {tmp}/good.json --config {tmp}/nosuch.yaml", ["nosuch.yaml"]),
    # sweep, perf
    ("sweep nosuch", ["nosuch", "eccentricity"]),
    ("sweep eccentricity --n 2", ["--n", "2"]),
    ("sweep eccentricity --png {tmp}/s.doc", ["--png", ".doc"]),
    ("perf --repeat 0", ["--repeat", "0"]),
    ("perf --json {tmp}/p.csv", ["--json", ".csv"]),
]

# valid questions without an answer: exit 1, at most three lines
NO_GAIT: list[tuple[str, list[str]]] = [
    # a regular pentagon at mu 0.3 has no stable grasp at all (thesis 3.3)
    ("plan pentagon --mu 0.3 --planner rule --point-contacts", ["mu"]),
    ("plan pentagon --mu 0.3 --planner back-and-forth --point-contacts", ["mu"]),
    ("plan pentagon --mu 0.3 --planner forward --point-contacts", ["mu"]),
    ("plan pentagon --mu 0.3 --planner optimal --point-contacts", ["mu"]),
    ("plan pentagon --mu 0.3 --planner best-first --point-contacts", ["mu"]),
    ("plan pentagon --mu 0.3 --planner modified --point-contacts", ["mu"]),
    ("plan ellipse --mu 0.7 --planner optimal --start 0,180 --point-contacts", ["360"]),
]


def _plan_variants(good: dict) -> dict[str, object]:
    """Careless edits of a good plan JSON, by file name."""
    def edit(fn) -> dict:
        q = json.loads(json.dumps(good))
        fn(q)
        return q

    return {
        "nonnum.json": edit(lambda q: q["steps"][0]["contacts"].update({"1": "abc"})),
        "mu_string.json": edit(lambda q: q.update(mu="0.7")),
        "no_steps.json": edit(lambda q: q.update(steps=[])),
        "bad_op.json": edit(lambda q: q["steps"][1].update(op="jump")),
        "bad_delta.json": edit(lambda q: q["steps"][1].update(delta="x")),
        "one_contact.json": edit(lambda q: q["steps"][0].update(contacts={"1": 50.0})),
        "finger_9.json": edit(lambda q: q["steps"][0].update(contacts={"1": 50.0, "9": 270.0})),
        "extra_key.json": edit(lambda q: q.update(colour="red")),
        "no_object.json": edit(lambda q: q.pop("object")),
        "bad_object.json": edit(lambda q: q.update(object="nosuch")),
    }


@pytest.fixture(scope="module")
def tmp(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("careless")
    (d / "bad.yaml").write_text("name: x\ntype: polygon\nvertices: [[0, 0], [1\n")
    (d / "empty.yaml").write_text("")
    (d / "unknown_key.yaml").write_text("name: c\ntype: circle\nradius: 0.05\ncolour: red\n")
    (d / "garbage.json").write_text("{not json")
    (d / "afile").write_text("a file, not a folder")
    good = d / "good.json"
    assert main(["plan", "pentagon", "--mu", "0.7", "--planner", "optimal", "--start", "50,270",
                 "--point-contacts", "--json", str(good)]) == 0
    for name, doc in _plan_variants(json.loads(good.read_text())).items():
        (d / name).write_text(json.dumps(doc))
    return d


def _run(argv: str, tmp: Path, capsys) -> tuple[int, list[str], set[str]]:
    import shlex

    before = {p.name for p in tmp.iterdir()}
    capsys.readouterr()
    rc = main(shlex.split(argv.format(tmp=tmp)))
    err = capsys.readouterr().err
    after = {p.name for p in tmp.iterdir()}
    return rc, [ln for ln in err.splitlines() if ln.strip()], after - before


def test_campaign_is_large_enough() -> None:
    assert len(BAD_INPUT) + len(NO_GAIT) >= 40
    assert len({a for a, _ in BAD_INPUT + NO_GAIT}) == len(BAD_INPUT) + len(NO_GAIT)


@pytest.mark.parametrize(("argv", "words"), BAD_INPUT, ids=[a for a, _ in BAD_INPUT])
def test_bad_input_exits_2_with_one_line(argv: str, words: list[str], tmp: Path,
                                         capsys) -> None:
    rc, lines, created = _run(argv, tmp, capsys)
    assert rc == 2, lines
    assert len(lines) == 1, lines
    assert "error" in lines[0] and "Traceback" not in lines[0]
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not created, f"refused input wrote {created}"


@pytest.mark.parametrize(("argv", "words"), NO_GAIT, ids=[a for a, _ in NO_GAIT])
def test_no_gait_exits_1_in_at_most_three_lines(argv: str, words: list[str], tmp: Path,
                                                capsys) -> None:
    rc, lines, created = _run(argv, tmp, capsys)
    assert rc == 1, lines
    assert 1 <= len(lines) <= 3, lines
    assert not any("Traceback" in ln for ln in lines)
    for w in words:
        assert any(w in ln for ln in lines), (w, lines)
    assert not created
