"""The operated run and its shadow (suppression the other way): two simulations of one model with the
same inputs and kicks, the law each runs, the kick schedule and the divergence guard's bounds."""
