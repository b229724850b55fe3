# Two commands on a fresh machine: `make demo` and `make test` (README).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

export MPLBACKEND := Agg
export MUJOCO_GL ?= egl

.PHONY: demo test test-all lint perf bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	mkdir -p out
	$(BIN)/graspgait map ellipse --mu 0.7 --theta 30 --png out/ellipse_map.png --npy out/ellipse_map.npy
	$(BIN)/graspgait map pentagon --mu 0.7 --png out/pentagon_map.png
	$(BIN)/graspgait sweep eccentricity --png out/sweep_eccentricity.png
	$(BIN)/graspgait plan pentagon --mu 0.7 --planner optimal --start 50,270 \
		--json out/pentagon_plan.json --motion out/pentagon_motion.txt --png out/pentagon_gait.png
	$(BIN)/graspgait perf
	@echo "demo figures written to out/"

test: $(STAMP)
	$(BIN)/python -m pytest -q

test-all: $(STAMP)
	$(BIN)/python -m pytest -q -m "slow or not slow"

lint: $(STAMP)
	$(BIN)/ruff check .

perf: $(STAMP)
	$(BIN)/graspgait perf

clean:
	rm -rf $(VENV) out .pytest_cache
