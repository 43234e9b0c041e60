"""Parameter sweeps of scenes, run locally or as Slurm job arrays: the plan and the local
runs (:mod:`.sweep`), job scripts and their options (:mod:`.slurm`), submission
(:mod:`.submit`), the state of a sweep's scenes (:mod:`.status`) and the run record of each
scene (:mod:`.provenance`). ``python -m layercontact sweep|status|collect`` drive them;
docs/sweeps.md and docs/clusters.md describe them."""
