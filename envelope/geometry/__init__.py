"""Ray casting and visibility against a triangle mesh."""
