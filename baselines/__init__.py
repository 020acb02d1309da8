"""The 2D methods: 2D-S and 2D-SS."""
