"""Volume rendering of the field: ray sampling, empty-space skipping and NeuS weights."""
