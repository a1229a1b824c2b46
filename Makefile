# make demo : set up .venv (first time) and reproduce the paper's cases, writing output/figures/
#             (not under version control) and comparing its records with figures/
# make figures : the same into figures/, the repository's (for the documentation)
# make test : set up .venv (first time) and run the test suite (ruff, mypy, pytest)
# make docs : set up .venv and the docs extra, build the site into docs/_build/html (-W)
# make docs-check : open the built site offline in headless Chromium (equations, screenshots)
VENV ?= .venv
PY := $(VENV)/bin/python
export PYVISTA_OFF_SCREEN := true
export OMP_NUM_THREADS := 1

.PHONY: setup demo figures test test-all lint bench docs docs-check clean

setup:
	@bash scripts/setup-venv.sh $(VENV)

demo: setup
	$(PY) demos/run_all.py

figures: setup
	$(PY) demos/run_all.py --figures figures

test: setup lint
	$(PY) -m pytest -n auto --dist loadfile tests

test-all: setup
	$(PY) -m pytest -n auto --dist loadfile tests -m "convergence or stress or slow or demo or not (convergence or stress or slow or demo)"

lint: setup
	$(VENV)/bin/ruff check unibuckle_fenicsx tests demos bench docs scripts
	$(VENV)/bin/ruff format --check unibuckle_fenicsx tests demos bench docs scripts
	$(VENV)/bin/mypy unibuckle_fenicsx

bench: setup
	$(PY) bench/bench_unilateral.py

# Warnings are errors and every cross-reference must resolve (-n: the external ones through
# the offline inventories of docs/_ext/unibuckle_docs.py); the build runs no solve (the CLI help, the schema, the demo pages
# and the bench tables are generated from the package and the stored results).
docs: setup
	@$(PY) -c 'import sphinx, myst_parser, furo, mathjax' 2>/dev/null || $(PY) -m pip install --quiet -e '.[docs]'
	@rm -rf docs/reference/_autosummary  # regenerated: a moved module leaves no stale page
	$(PY) -m sphinx -n -W --keep-going -q -b html docs docs/_build/html
	@$(PY) scripts/check_site.py docs/_build/html

# The built site opened offline in headless Chromium (apt-get install chromium): every
# equation typeset with the network off, and a screenshot per page kind to look at.
docs-check: docs
	$(PY) scripts/check_site.py --browser --screenshots docs/_build/screenshots docs/_build/html

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info docs/_build docs/_generated docs/reference/_autosummary
