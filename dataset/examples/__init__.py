"""Small example inputs shipped for tests and docs (each with the script that makes it)."""
