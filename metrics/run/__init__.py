"""Running methods on scenes: options, caches, executors, masks and degradations."""
