"""The gain explorer: the closed loop linearised off the loop thread, its poles, root loci and gain map,
and the decay measured after a kick beside the one predicted."""
