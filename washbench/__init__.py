"""washbench: a testbed for flight-simulator motion cueing (washout algorithms)."""

__version__ = "0.1.0"
