"""The study's answer and its pictures (docs/study.md): the decision between the contact
models (:mod:`.decision`), the verdict's tables and summary (:mod:`.summary`), a scene
compared with the measured images (:mod:`.scene_comparison`), the study's map and curve
figures (:mod:`.figures`, :mod:`.flattening_maps` for Fig. B.9, :mod:`.load_series_maps` for
Fig. B.11) and the pipeline's plots of its measurements and simulations (:mod:`.plots`).
Nothing is imported here: a job that needs one module pays for that one (the summary reads
no matplotlib)."""
