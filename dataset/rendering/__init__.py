"""Cameras and rendering: the one ray caster (embree), rendered modalities and shading, the
facade views, visibility from outside and cross-sections."""
