"""Pure functions over traces: metrics, ranking."""
