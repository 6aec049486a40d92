"""What the Snakemake workflow needs to build its DAG, importable and tested without
Snakemake (tests/workflow_dag/): run paths (:mod:`~amontons.workflow.paths`), the selected
spheres (:mod:`~amontons.workflow.spheres`: their sheet rows, raw files, pixel sizes, optional
inputs and hold-outs, one module each), config slices as params
(:mod:`~amontons.workflow.params`), the expansion of scenes and scans
(:mod:`~amontons.workflow.scenes`), the study (:mod:`~amontons.workflow.study`), targets
(:mod:`~amontons.workflow.targets`), the accuracy study (:mod:`~amontons.workflow.accuracy`)
and cluster resources (:mod:`~amontons.workflow.resources`), tied together by
:class:`~amontons.workflow.run.WorkflowRun`. Standard library, jsonschema and yaml only: no
numerical stack is loaded to build a DAG.
"""
