"""Training: scene pixels and the scene box, losses and held-out evaluation."""
