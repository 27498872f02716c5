"""Core: periodic matrices, LTP state-space systems, simulation, Floquet theory, discretization and lifting."""
