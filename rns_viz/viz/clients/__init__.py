"""Who is connected and who may operate: the operator lock's per-client panel, the password modal and
notifications to one client or all."""
