"""App tests: the viser server (start_app, scene, panels), driven through its API or protocol-level clients;
no browser."""
