"""The study's answer and its pictures (docs/study.md): the decision between the contact
models (:mod:`.decision`), the verdict's tables and summary (:mod:`.summary`), the study's
map and curve figures (:mod:`.figures`) and the pipeline's plots of its measurements and
simulations (:mod:`.plots`). Nothing is imported here: a job that needs one module pays for
that one (the summary reads no matplotlib)."""
