"""Error measures: facade matching, per-building errors, aggregation, bootstrap."""
