"""Trajectories from observed positions (``orbit: {observed: true}``): per-object straight
lines through each observation's position (:mod:`.observed_position`) and the grouping of
many objects' rows into non-overlapping layers (:mod:`.observed_objects`)."""
