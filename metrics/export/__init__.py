"""Exports for energy tools (CSV, IDF geometry, CityJSON): python -m metrics.export."""
