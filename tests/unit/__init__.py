"""Unit tests: pure functions, physics, laws and simulations; no Session, no server, no browser.

The developer's loop: python -m pytest tests/unit
"""
