# Two entry points for humans: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
STAMP  := $(VENV)/.installed
DEMO   := demo_out

.PHONY: venv demo test

venv: $(STAMP)

# torch is installed first and on its own so pip keeps the CPU wheel instead of
# resolving a CUDA build while solving the whole dependency set.
$(STAMP): pyproject.toml
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install torch==2.13.0
	$(VENV)/bin/pip install -e '.[test]'
	touch $(STAMP)

# The independent simulators of rigs/ write the records that demo step 6 calibrates to, step 8
# diagnoses (the same gearbox with the rig's own casing resonance) and step 9 scores the transfer
# on (twin/ never imports rigs/ or bench/: it reads their files). After step 8, bench/ scores its
# model before and after twin improve with a distance written apart from twin.compare.
RIG_RECORDS := --records-per-stage 3 --record-duration 0.3 --damage-sampling snapshot --damage-scatter 0.1 --no-progress

demo: venv
	mkdir -p $(DEMO)/rigs
	$(VENV)/bin/python -m rigs.lumped target scenarios/lubricated.yaml --out $(DEMO)/rigs/lumped.h5 --seed 3 $(RIG_RECORDS)
	$(VENV)/bin/python -m rigs.ltca target scenarios/lubricated.yaml --out $(DEMO)/rigs/ltca.h5 --seed 4 $(RIG_RECORDS)
	$(VENV)/bin/python -m rigs.pedestal steady --gearbox 3 --scatter 0.12 --seed 3 --duration 2 --out $(DEMO)/rigs/pedestal_steady.h5
	$(VENV)/bin/python -m rigs.pedestal runup --gearbox 3 --scatter 0.12 --seed 3 --from 2 --to 20 --duration 6 --out $(DEMO)/rigs/pedestal_runup.h5
	$(VENV)/bin/python -m rigs.pedestal impact --gearbox 3 --scatter 0.12 --seed 3 --speed 0.5 --duration 8 --location pinion_pedestal --out $(DEMO)/rigs/pedestal_hammer.h5
	$(VENV)/bin/python -m rigs.pedestal impact --gearbox 3 --scatter 0.12 --seed 3 --speed 0.5 --duration 8 --location gear_pedestal --out $(DEMO)/rigs/pedestal_hammer_gear.h5
	$(VENV)/bin/python -m rigs.pedestal steady --gearbox 3 --scatter 0.12 --seed 5 --duration 2 --load 5 --out $(DEMO)/rigs/pedestal_light.h5
	$(VENV)/bin/python -m rigs.pedestal steady --gearbox 3 --scatter 0.12 --seed 7 --duration 2 --out $(DEMO)/rigs/pedestal_steady_again.h5
	$(VENV)/bin/python -m rigs.pedestal steady --gearbox 3 --scatter 0.12 --seed 4 --duration 2 --effect casing_resonance --out $(DEMO)/rigs/pedestal_casing_steady.h5
	$(VENV)/bin/python -m rigs.pedestal runup --gearbox 3 --scatter 0.12 --seed 4 --from 2 --to 20 --duration 6 --effect casing_resonance --out $(DEMO)/rigs/pedestal_casing_runup.h5
	$(VENV)/bin/python -m rigs.pedestal steady --gearbox 3 --scatter 0.12 --seed 6 --duration 2 --effect bearing_outer_race --out $(DEMO)/rigs/pedestal_bearing.h5
	$(VENV)/bin/twin demo --out $(DEMO) --rig-records $(DEMO)/rigs/lumped.h5 $(DEMO)/rigs/ltca.h5 \
		--calibration-records $(DEMO)/rigs/pedestal_steady.h5 $(DEMO)/rigs/pedestal_runup.h5 $(DEMO)/rigs/pedestal_hammer.h5 $(DEMO)/rigs/pedestal_hammer_gear.h5 $(DEMO)/rigs/pedestal_light.h5 $(DEMO)/rigs/pedestal_steady_again.h5 \
		--hidden-effect-records $(DEMO)/rigs/pedestal_casing_steady.h5 $(DEMO)/rigs/pedestal_casing_runup.h5
	@printf '\n[6/9, continued] step 6: its calibrated twin against a record of the same gearbox with a rolling-bearing defect (outside the effect catalogue): twin compare names the series of its impacts in the envelope (envelope_line, drawn in compare_bearing/compare.png)\n'
	$(VENV)/bin/twin compare $(DEMO)/calibration_rig/calibrated.yaml --measurements $(DEMO)/rigs/pedestal_bearing.h5 --out $(DEMO)/compare_bearing
	@printf '\n[8/9, scored apart] step 8: the model before and after twin improve against the record, by bench/\n'
	$(VENV)/bin/python bench/spectral_distance.py $(DEMO)/rig/pedestal_hidden.h5 --record steady --models $(DEMO)/loop/models.h5

# Two worker processes, whole test files to each (module fixtures are computed once), the files
# with slow tests first (tests/conftest.py; xdist would otherwise send the largest files first);
# the session FMUs are built once and shared. `make test PYTEST_ARGS=-n0` runs in one process.
PYTEST_ARGS ?= -n 2 --dist loadfile --no-loadscope-reorder

test: venv
	$(VENV)/bin/python -m pytest $(PYTEST_ARGS)
