"""The executor's parts (thesis 7.4.2 move sequences, 7.4.6 servo loop, the ground-truth
monitor) never import one another: each imports only the shared modules below them, and
the task (executor) composes them. The public import paths stay."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import graspgait_env.sim as sim_pkg

SIM = Path(sim_pkg.__file__).parent
PARTS = {"moves", "servo_loop", "monitor"}
SHARED = {"state", "frames"}


def _sim_imports(module: str) -> set[str]:
    tree = ast.parse((SIM / f"{module}.py").read_text(encoding="utf-8"))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            if node.module.startswith("graspgait_env.sim."):
                out.add(node.module.split(".")[2])
            elif node.module == "graspgait_env.sim":
                out |= {a.name for a in node.names}
        elif isinstance(node, ast.Import):
            out |= {a.name.split(".")[2] for a in node.names
                    if a.name.startswith("graspgait_env.sim.")}
    return out


@pytest.mark.parametrize("part", sorted(PARTS))
def test_the_parts_do_not_import_each_other(part):
    imported = _sim_imports(part)
    assert not imported & (PARTS | {"executor", "simulate"}), imported


@pytest.mark.parametrize("shared", sorted(SHARED))
def test_the_shared_modules_import_no_part(shared):
    assert not _sim_imports(shared) & (PARTS | {"executor", "simulate"})


def test_frames_import_nothing_of_the_simulator():
    assert _sim_imports("frames") == set()


def test_the_public_import_paths_stay():
    from graspgait_env.sim import (
        GaitExecutor,
        StepReport,
        executor,
        random_pose_perturbation,
        state,
    )

    assert executor.GaitExecutor is GaitExecutor
    assert executor.StepReport is StepReport is state.StepReport
    assert executor.random_pose_perturbation is random_pose_perturbation
    for name in executor.__all__:
        assert hasattr(executor, name), name
