# Two entry points, each doing its own set-up from a fresh clone with only Python 3.11 and pip:
#   make reproduce   full reproduction (config/config.yaml) + HTML report
#   make test        the whole test suite (units, solver oracles, lint, dry runs, small-data run)
# and, as root where Debian's packages can be installed (CI runs it after make test):
#   make test-cluster the small run through a real one-node SLURM (tests/cluster, docs/cluster.md)
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
CORES  ?= all

BASE   ?= HEAD
# One test process more than cores: a Snakemake run of the tests has serial stretches (its DAG,
# its last tables, its report) that a third process fills (13.6 against 14.2 min on 2 cores).
TEST_WORKERS ?= $(shell echo $$(( $$(nproc) + 1 )))

.PHONY: reproduce test test-cluster install golden-bits clean-venv

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

# Re-install whenever the declared dependencies change, with uv, itself installed by the venv's
# pip (which reads pip.conf) where the venv has none yet: uv resolves to the same releases as
# pip (the two venvs' package lists compared equal, 2026-11-30) and installs them in some 40
# s less on 2 cores, at the start of make test, when nothing else can run yet. uv reads its
# own settings (UV_DEFAULT_INDEX, uv.toml), not pip.conf nor PIP_* (docs/deploy.md).
# --compile-bytecode because uv, unlike pip, compiles none unless asked: where
# PYTHONDONTWRITEBYTECODE is set, as on the developers' machines, nothing would ever compile
# the packages' modules, and every process of the tests would parse them anew. (Letting
# Python write the bytecode of what is imported instead made the suite slower by more than
# the install saved, its processes compiling the same modules at once: make test 1244 s from
# a fresh clone with pip, against 1213 to 1242 s.)
$(STAMP): pyproject.toml | $(BIN)/python
	test -x $(BIN)/uv || $(BIN)/python -m pip install --quiet "uv>=0.5"
	$(BIN)/uv pip install --quiet --python $(BIN)/python --compile-bytecode -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

reproduce: $(STAMP)
	# the solver's kernels into numba's cache (if cold) before the first job, not inside it
	$(BIN)/python -c "from amontons.contact.kernel_cache import main; main()"
	$(BIN)/snakemake --profile profiles/default --cores $(CORES) --configfile config/config.yaml
	$(BIN)/snakemake --profile profiles/default --cores $(CORES) --configfile config/config.yaml \
		--report results/full/report.html

# Every core runs tests (pytest-xdist, TEST_WORKERS processes): one test module per process at
# a time, so that a module's fixtures run once, and the modules that start long Snakemake runs
# first (tests/conftest.py).
test: $(STAMP)
	# the solver's kernels into numba's cache (if cold) once, beside the tests: a test process
	# or Snakemake job that needs them meanwhile waits on the warm-up's lock, then loads them
	# (amontons.contact.jit); pytest's start and the first data sets need no kernel
	$(BIN)/python -c "from amontons.contact.kernel_cache import main; main()" & warm=$$!; \
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadscope \
		--no-loadscope-reorder; tests=$$?; \
	wait $$warm || { echo "make test: the kernel warm-up failed" >&2; exit 1; }; exit $$tests

# The workflow through a real one-node SLURM with its accounting database (tests/cluster):
# it installs and starts system services as root, which make test may not do on a user's
# machine. The preflight installs what is missing, or stops at once saying why (no root, no
# package registry), while the kernels compile (if cold); the tests start the cluster and
# stop it, their first solve waiting for the kernels as make test's do.
test-cluster: $(STAMP)
	$(BIN)/python -c "from amontons.contact.kernel_cache import main; main()" & warm=$$!; \
	tests/cluster/start_slurm.sh preflight || { kill $$warm; exit 2; }; \
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pytest --cluster tests/cluster; tests=$$?; \
	wait $$warm || { echo "make test-cluster: the kernel warm-up failed" >&2; exit 1; }; \
	exit $$tests

# A rebuild's same-machine check: the golden cases solved by BASE's solver and by the working
# tree's, here, compared to the last bit (tests/contact/golden/same_bits.py).
golden-bits: $(STAMP)
	$(BIN)/python tests/contact/golden/same_bits.py --base $(BASE)

clean-venv:
	rm -rf $(VENV)
