"""The validation study (docs/study.md §7): virtual spheres whose truth is each contact model,
solved finer than the study solves them, judged by the study's own scans and decision."""
