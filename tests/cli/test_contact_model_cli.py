"""``graspgait plan`` plans for the hand by default and records it; ``--point-contacts``
gives the thesis's maps; ``graspgait simulate`` warns, in one line, about point plans."""

from __future__ import annotations

import json

import pytest

from graspgait_env.cli import main
from graspgait_env.contact_model import hand_contact_model


def _plan(tmp_path, *flags: str, turn: str = "60") -> dict:
    path = tmp_path / "plan.json"
    assert main(["plan", "circle", "--mu", "0.7", "--planner", "optimal", "--turn", turn,
                 "--json", str(path), *flags]) == 0
    return json.loads(path.read_text())


def test_plan_uses_the_hand_by_default(tmp_path, capsys):
    d = _plan(tmp_path)
    assert d["contact_model"] == hand_contact_model("circle").to_json()
    assert "contact model: hand: ball tips 7.8 mm" in capsys.readouterr().out


def test_point_contacts_flag_gives_the_thesis_maps(tmp_path, capsys):
    d = _plan(tmp_path, "--point-contacts")
    assert d["contact_model"]["name"] == "point"
    assert "point contacts" in capsys.readouterr().out
    # the thesis circle's point-contact start is 120 deg apart; the hand's is wider
    hand = _plan(tmp_path)
    gap = lambda c: abs(float(c["2"]) - float(c["1"]))  # noqa: E731
    assert gap(d["steps"][0]["contacts"]) < gap(hand["steps"][0]["contacts"])


def test_sim_config_sets_the_hand(tmp_path):
    cfg = tmp_path / "sim.yaml"
    cfg.write_text("grip_force: 3.0\n")
    assert _plan(tmp_path, "--sim-config", str(cfg))["contact_model"]["grip_n"] == 3.0


def test_sim_config_with_point_contacts_is_refused(tmp_path, capsys):
    rc = main(["plan", "circle", "--mu", "0.7", "--planner", "optimal", "--point-contacts",
               "--sim-config", "x.yaml"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0 and "--point-contacts" in err


@pytest.mark.parametrize("flags,warns", [((), False), (("--point-contacts",), True)])
def test_simulate_warns_once_about_point_plans(tmp_path, capsys, flags, warns):
    _plan(tmp_path, *flags, turn="10")
    capsys.readouterr()
    main(["simulate", str(tmp_path / "plan.json"), "--quiet"])
    err = [ln for ln in capsys.readouterr().err.splitlines() if "warning" in ln]
    assert len(err) == (1 if warns else 0)
    if warns:
        assert "point contacts" in err[0] and "--point-contacts" in err[0]
