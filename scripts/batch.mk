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

LODREFINE ?= build/lodrefine
RUN ?= run
ARGS ?=
SCRIPTS := $(dir $(lastword $(MAKEFILE_LIST)))
export LODREFINE ARGS
# The per-building command; `make ... todo` only lists the ids a run would (re)do, one a line
# (how scripts/parallel_batch.sh and scripts/slurm_batch.sh pick their work).
REFINE_ONE := $(SCRIPTS)refine_one.sh
ifeq ($(MAKECMDGOALS),todo)
REFINE_ONE := printf '%.0s%s\n'
endif

LOCK := $(shell $(SCRIPTS)batch_lock.sh '$(RUN)')
ifneq ($(LOCK),ok)
$(error $(LOCK))
endif

IDS := $(sort $(patsubst $(RUN)/%/coarse.obj,%,$(wildcard $(RUN)/*/coarse.obj)))
TOTAL := $(words $(IDS))
# A failed building's output is FAILED, a refined one's its model and report.
OUTPUTS := $(foreach id,$(IDS),$(if $(wildcard $(RUN)/$(id)/FAILED),$(RUN)/$(id)/FAILED,\
             $(RUN)/$(id)/refined.obj $(RUN)/$(id)/report.json))

# The list of buildings, rewritten only when it changes: a removed building refreshes the summary.
$(shell printf '%s\n' $(IDS) > '$(RUN)/.ids.tmp' && \
        { cmp -s '$(RUN)/.ids.tmp' '$(RUN)/.ids' && rm -f '$(RUN)/.ids.tmp' || mv -f '$(RUN)/.ids.tmp' '$(RUN)/.ids'; })

.PHONY: all refined todo clean-results
all: $(RUN)/summary.txt
refined: $(OUTPUTS)  # every building, without the summary
todo: $(OUTPUTS)

# One building (both targets come from one run): never fails the batch.
$(RUN)/%/refined.obj $(RUN)/%/report.json: $(RUN)/%/coarse.obj $(RUN)/%/cloud.ply
	@$(REFINE_ONE) '$(RUN)' '$*'

$(RUN)/%/FAILED: $(RUN)/%/coarse.obj $(RUN)/%/cloud.ply
	@$(REFINE_ONE) '$(RUN)' '$*'

$(RUN)/summary.txt: $(OUTPUTS) $(RUN)/.ids
	@mkdir -p $(RUN)/plots
	@tmp='$@.tmp.'$$$$; $(LODREFINE) eval --dir $(RUN) --json $(RUN)/summary.json --csv $(RUN)/summary.csv \
	    --svg-dir $(RUN)/plots --html $(RUN)/report.html > "$$tmp" && mv -f "$$tmp" $@ || { rm -f "$$tmp"; exit 1; }
	@cat $@
	@echo "report: $(RUN)/report.html"
	@echo "failed: $$(ls $(RUN)/*/FAILED 2>/dev/null | wc -l) of $(TOTAL) (see $(RUN)/<id>/FAILED)"

clean-results:
	rm -f $(RUN)/*/FAILED $(RUN)/*/refined.obj $(RUN)/*/report.json $(RUN)/*/log.txt $(RUN)/*/done $(RUN)/summary.* $(RUN)/.ids
