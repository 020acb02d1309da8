"""Error measures, comparison tables and plots."""
