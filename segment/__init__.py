"""Masks from RGB: a semantic segmenter trained on renders that are never evaluated.

``network`` (a compact U-Net) ← ``weights`` (the weights file and its training record) ←
``segmenter`` (RGB -> class ids, the built-in network or a plugin) ← ``scene_masks`` (a
scene copy whose semantic images are the segmenter's). Training: ``augment``,
``training_data``, ``train`` (CLI); measuring: ``evaluate`` (CLI); mask copies of your
scenes: ``predict`` (CLI). See docs/segment.md.
"""
