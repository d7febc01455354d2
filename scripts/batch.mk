# Refine every building of a run folder, in parallel, resumable.
#
#   make -f scripts/batch.mk RUN=run -j8 [LODREFINE=build/lodrefine] [ARGS="--tau-cov 0.3"]
#
# RUN/<id>/coarse.obj and RUN/<id>/cloud.ply are the inputs (`lodrefine crop` or
# `lodrefine synth` make them). Each building is refined by scripts/refine_one.sh (the same
# command the GNU Parallel and Slurm dispatchers run): RUN/<id>/refined.obj, report.json and
# log.txt, or RUN/<id>/FAILED with its one-line reason; the batch goes on either way.
# Resumable: a building is redone when refined.obj or report.json is missing or older than
# coarse.obj/cloud.ply; a failed one when FAILED is (delete FAILED to retry it). Safe to kill
# (even SIGKILL): rerun and only what is missing is done. One run per folder at a time (a lock,
# RUN/.batch.lock); a second one stops with one line. At the end, and whenever any building
# changed, `lodrefine eval --dir` pools the figures into RUN/summary.{txt,json,csv}, RUN/plots/
# and RUN/report.html.
#
# Building folder names are data (ids from a city file): the run stops with one line, before
# anything runs, when one is not a safe name ([A-Za-z0-9._-], not starting with '-' or '.';
# `lodrefine crop` and `convert` only make such names). RUN itself may hold spaces: the batch
# runs inside it (make -C), so no target or recipe holds the RUN path.

LODREFINE ?= build/lodrefine
RUN ?= run
ARGS ?=
BATCH_MK := $(abspath $(lastword $(MAKEFILE_LIST)))
SCRIPTS := $(dir $(BATCH_MK))
# A word for the shell in single quotes.
quote = '$(subst ','\'',$(1))'

.PHONY: all refined todo clean-results

ifndef LODREFINE_BATCH_DIR
# The calling make: checks the names and takes RUN's lock (for as long as it lives), then runs
# the batch inside RUN.
LOCK := $(shell $(call quote,$(SCRIPTS)batch_lock.sh) $(call quote,$(RUN)))
ifneq ($(LOCK),ok)
$(error $(LOCK))
endif
BINARY := $(if $(findstring /,$(LODREFINE)),$(abspath $(LODREFINE)),$(LODREFINE))

INNER = $(MAKE) --no-print-directory -C $(call quote,$(RUN)) -f $(call quote,$(BATCH_MK)) \
        LODREFINE_BATCH_DIR=$(call quote,$(RUN)) LODREFINE=$(call quote,$(BINARY))
all refined todo clean-results:
	@+$(INNER) $@
# One building's output, e.g. RUN/<id>/refined.obj.
.DEFAULT:
	@+$(INNER) $(call quote,$(subst $(RUN)/,,$@))

else
# Inside RUN: every name below is a checked building folder name or a fixed one.
export LODREFINE ARGS LODREFINE_BATCH_DIR
# The per-building command; `make ... todo` only lists the ids a run would (re)do, one a line
# (how scripts/parallel_batch.sh and scripts/slurm_batch.sh pick their work).
REFINE_ONE := $(call quote,$(SCRIPTS)refine_one.sh) .
ifeq ($(MAKECMDGOALS),todo)
REFINE_ONE := printf '%s\n'
endif

IDS := $(sort $(patsubst %/coarse.obj,%,$(wildcard */coarse.obj)))
TOTAL := $(words $(IDS))
# A failed building's output is FAILED, a refined one's its model and report.
OUTPUTS := $(foreach id,$(IDS),$(if $(wildcard $(id)/FAILED),$(id)/FAILED,$(id)/refined.obj $(id)/report.json))

# The list of buildings, rewritten only when it changes: a removed building refreshes the summary.
$(file >.ids.new,$(IDS))
$(shell cmp -s .ids.new .ids && rm -f .ids.new || mv -f .ids.new .ids)

all: summary.txt
refined: $(OUTPUTS)  # every building, without the summary
todo: $(OUTPUTS)

# One building (both targets come from one run): never fails the batch.
%/refined.obj %/report.json: %/coarse.obj %/cloud.ply
	@$(REFINE_ONE) '$*'

%/FAILED: %/coarse.obj %/cloud.ply
	@$(REFINE_ONE) '$*'

summary.txt: $(OUTPUTS) .ids
	@mkdir -p plots
	@tmp=$$(mktemp .lodrefine-tmp-XXXXXXXXXX) && chmod 644 "$$tmp" && \
	    "$$LODREFINE" eval --dir "$$PWD" --json "$$PWD/summary.json" --csv "$$PWD/summary.csv" \
	    --svg-dir "$$PWD/plots" --html "$$PWD/report.html" > "$$tmp" && mv -f "$$tmp" $@ || { rm -f "$$tmp"; exit 1; }
	@cat $@
	@echo "report: $$LODREFINE_BATCH_DIR/report.html"
	@echo "failed: $$(ls */FAILED 2>/dev/null | wc -l) of $(TOTAL) (see $$LODREFINE_BATCH_DIR/<id>/FAILED)"

clean-results:
	rm -f */FAILED */refined.obj */report.json */log.txt */done summary.* .ids
endif
