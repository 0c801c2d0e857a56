"""Where the arm can go without moving the base: the current reactionless path as a table over its path
integral (1-D RNS), the reactionless-reachable set (otherwise) and the arm's reach."""
