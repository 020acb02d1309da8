"""Where work runs: worker pools on this machine, Ray tasks on a cluster, and folders packed
to travel between them."""
