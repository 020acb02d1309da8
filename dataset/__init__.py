"""The synthetic benchmark: procedural buildings, ground truth, cameras, renderer, scene I/O."""
