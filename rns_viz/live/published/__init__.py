"""The immutable records readers take from the loop: the snapshot and its parts (settings, readouts,
overlays, notices, the lesson and replay in progress), recordings, and the plots' ring buffers."""
