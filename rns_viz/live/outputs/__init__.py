"""What the loop books from the runs after every step: plot samples, readouts (distances to singularity,
the null-space vector), the arm's reaction on the base (Eq. 1) and the always-on recorder."""
