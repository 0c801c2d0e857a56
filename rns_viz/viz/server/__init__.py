"""The app's server: :func:`~rns_viz.viz.server.app.start_app` builds the viser server, panels and scene
around a session; the render thread sends what changed; each page is paced to the rate it draws at."""
