"""What the operator drives: the joint and end-effector references both runs follow, the references
that move while the simulation runs (paths, resolved rate, smoothed targets), trep2's task-arm target,
and the lock that says which client may operate."""
