"""Session tests: a headless Session (stepped, or real time), its loop, lessons and replay; no viser server."""
