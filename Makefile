# make demo : set up .venv (first time) and reproduce the paper's cases, writing figures/
# make test : set up .venv (first time) and run the test suite (ruff, mypy, pytest)
VENV ?= .venv
PY := $(VENV)/bin/python
export PYVISTA_OFF_SCREEN := true
export OMP_NUM_THREADS := 1

.PHONY: setup demo test test-all lint bench clean

setup:
	@bash scripts/setup-venv.sh $(VENV)

demo: setup
	$(PY) demos/run_all.py

test: setup lint
	$(PY) -m pytest tests

test-all: setup
	$(PY) -m pytest tests -m "convergence or stress or not (convergence or stress)"

lint: setup
	$(VENV)/bin/ruff check unibuckle_fenicsx tests demos bench
	$(VENV)/bin/ruff format --check unibuckle_fenicsx tests demos bench
	$(VENV)/bin/mypy unibuckle_fenicsx

bench: setup
	$(PY) bench/bench_unilateral.py

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info
