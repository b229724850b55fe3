# Two commands on a fresh machine: `make demo` and `make test` (README).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# the CPU wheel of torch on this machine's disk; the package itself gives only a lower bound
TORCH_VERSION ?= 2.13.0

export MPLBACKEND := Agg
export MUJOCO_GL ?= egl

.PHONY: demo test test-all lint perf bench docs gallery clean

$(STAMP): pyproject.toml
	@echo "==> creating the virtual environment $(VENV)"
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	@echo "==> installing the CPU wheel of torch (pinned here, not in the package: the package"
	@echo "    asks only for torch>=2.1, and an unpinned install would pull a CUDA build)"
	$(BIN)/python -m pip install --progress-bar on 'torch==$(TORCH_VERSION)'
	@echo "==> installing graspgait_env with every extra into $(VENV) (NumPy, MuJoCo, Gymnasium;"
	@echo "    [train] stable-baselines3, sb3-contrib, TensorBoard; [ray]; [zoo]; [video]; [dev]"
	@echo "    test tools; [docs] the documentation site; about a minute on a fresh machine)"
	$(BIN)/python -m pip install --progress-bar on -e '.[all,dev,docs]' 'torch==$(TORCH_VERSION)'
	touch $(STAMP)
	@echo "==> $(VENV) is ready"

demo: $(STAMP)
	mkdir -p out
	@echo "==> grasp maps of the ellipse (finger pair boxes at theta = 30 deg) and the pentagon"
	$(BIN)/graspgait map ellipse --mu 0.7 --theta 30 --png out/ellipse_map.png --npy out/ellipse_map.npy
	$(BIN)/graspgait map pentagon --mu 0.7 --png out/pentagon_map.png
	@echo "==> stable fraction of the grasp map against eccentricity and friction (thesis figs. 3.8-3.9)"
	$(BIN)/graspgait sweep eccentricity --png out/sweep_eccentricity.png
	@echo "==> the fewest-regrasp gait of the pentagon from the thesis's start (fig. 4.6), and the rule-based one"
	$(BIN)/graspgait plan pentagon --mu 0.7 --planner optimal --start 50,270 --point-contacts \
		--json out/pentagon_plan.json --motion out/pentagon_motion.txt --png out/pentagon_gait.png
	$(BIN)/graspgait plan pentagon --mu 0.7 --planner rule \
		--json out/pentagon_rule_plan.json --png out/pentagon_rule_gait.png
	@echo "==> the ellipse's story, no training: the rule-based, optimal and learned gaits from one"
	@echo "    start, on the grasp map with a comparison table (the shipped agent general)"
	$(BIN)/graspgait story general --object ellipse --out out
	@echo "==> the learned gait executed on the simulated MuJoCo hand, with a video"
	$(BIN)/graspgait simulate out/ellipse_learned_plan.json --video out/ellipse_learned.mp4
	@echo
	@echo "demo: made these files in $(CURDIR)/out:"
	@ls -1 out | sed 's/^/  out\//'
	@echo "(performance targets: make perf)"

test: $(STAMP)
	$(BIN)/python -m pytest -q

test-all: $(STAMP)
	$(BIN)/python -m pytest -q -m "slow or not slow"

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/lint-imports

perf: $(STAMP)
	$(BIN)/graspgait perf

# the documentation site (mkdocs.yml, docs/) into site/, strict: a broken link, a missing
# page or a reference to a renamed function fails the build
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# docs/gallery/: grasp maps, gait figures and the learned gaits on the MuJoCo hand
# (the commands docs/gallery.md names; about two minutes). Each object's story plays its
# own shipped agent where it has one, else general (the ellipse's, the pentagon's and the
# hexagon's agents are retired).
GALLERY_OBJECTS := circle ellipse pentagon hexagon
OWN_AGENTS := circle
gallery: $(STAMP)
	mkdir -p docs/gallery out/gallery
	for o in $(GALLERY_OBJECTS); do \
		$(BIN)/graspgait map $$o --mu 0.7 --png docs/gallery/$${o}_map.png || exit 1; \
		case " $(OWN_AGENTS) " in *" $$o "*) a=$$o;; *) a=general;; esac; \
		$(BIN)/graspgait story $$a --object $$o --out out/gallery || exit 1; \
		cp out/gallery/$${o}_story.png docs/gallery/$${o}_story.png; \
		$(BIN)/graspgait simulate out/gallery/$${o}_learned_plan.json \
			--video docs/gallery/$${o}_learned.mp4 --quiet || exit 1; \
	done
	$(BIN)/graspgait map ellipse --mu 0.7 --theta 30 --png docs/gallery/ellipse_map_theta30.png
	$(BIN)/graspgait sweep eccentricity --png docs/gallery/sweep_eccentricity.png
	$(BIN)/graspgait plan pentagon --mu 0.7 --planner optimal --start 50,270 --point-contacts \
		--json out/gallery/pentagon_fig46_plan.json --png docs/gallery/pentagon_fig46_gait.png

clean:
	rm -rf $(VENV) out site .pytest_cache
