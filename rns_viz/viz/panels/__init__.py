"""The control panel: every GUI folder and control, each input wired to one session command, the
live plots and the panel's text (units, readouts, the model menu)."""
