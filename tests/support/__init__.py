"""What the tests share: the browser recipe, app and session helpers, the protocol client, log readers and
the independent oracles (MuJoCo, the paper's closed forms)."""
