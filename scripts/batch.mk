# Refine every building of a run folder, in parallel, resumable.
#
#   make -f scripts/batch.mk RUN=run -j8 [LODREFINE=build/lodrefine] [ARGS="--tau-cov 0.3"]
#
# RUN/<id>/coarse.obj and RUN/<id>/cloud.ply are the inputs (`lodrefine crop` or
# `lodrefine synth` make them). Per building it writes RUN/<id>/refined.obj, report.json and
# log.txt; a building that fails gets RUN/<id>/FAILED with its one-line reason and the batch
# goes on. Buildings already done are skipped (delete refined.obj/FAILED to redo one).
# At the end `lodrefine eval --dir` pools the figures into RUN/summary.{txt,json,csv} and
# RUN/plots/.

LODREFINE ?= build/lodrefine
RUN ?= run
ARGS ?=

IDS := $(sort $(patsubst $(RUN)/%/coarse.obj,%,$(wildcard $(RUN)/*/coarse.obj)))
DONE := $(addprefix $(RUN)/,$(addsuffix /done,$(IDS)))
TOTAL := $(words $(IDS))

.PHONY: all clean-results
all: $(RUN)/summary.txt

# One building: never fails the batch; the outcome is recorded in `done`.
$(RUN)/%/done: $(RUN)/%/coarse.obj $(RUN)/%/cloud.ply
	@rm -f $(RUN)/$*/FAILED
	@if $(LODREFINE) refine --model $(RUN)/$*/coarse.obj --cloud $(RUN)/$*/cloud.ply \
	      --out $(RUN)/$*/refined.obj --report $(RUN)/$*/report.json $(ARGS) > $(RUN)/$*/log.txt 2>&1; then \
	    echo "ok $*" > $@; \
	    echo "[$$(ls $(RUN)/*/done 2>/dev/null | wc -l)/$(TOTAL)] $$(tail -n 1 $(RUN)/$*/log.txt)"; \
	else \
	    tail -n 1 $(RUN)/$*/log.txt > $(RUN)/$*/FAILED; echo "failed $*" > $@; \
	    echo "[$$(ls $(RUN)/*/done 2>/dev/null | wc -l)/$(TOTAL)] FAILED $*: $$(cat $(RUN)/$*/FAILED)"; \
	fi

$(RUN)/summary.txt: $(DONE)
	@mkdir -p $(RUN)/plots
	@$(LODREFINE) eval --dir $(RUN) --json $(RUN)/summary.json --csv $(RUN)/summary.csv \
	    --svg-dir $(RUN)/plots > $(RUN)/summary.tmp && mv $(RUN)/summary.tmp $@
	@cat $@
	@echo "failed: $$(ls $(RUN)/*/FAILED 2>/dev/null | wc -l) of $(TOTAL) (see $(RUN)/<id>/FAILED)"

clean-results:
	rm -f $(RUN)/*/done $(RUN)/*/FAILED $(RUN)/*/refined.obj $(RUN)/*/report.json $(RUN)/*/log.txt $(RUN)/summary.*
