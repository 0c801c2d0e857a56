"""Independent test oracles: reference implementations that share no code with ``rns_viz``.

They may import heavy test-only dependencies (MuJoCo); nothing in ``rns_viz/`` imports them.
"""
