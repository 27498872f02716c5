"""Frequency domain: harmonic transfer functions, their plots and the harmonic state space."""
