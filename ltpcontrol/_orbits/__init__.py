"""Rhythmic plants: hybrid plants, periodic orbits, their linearization and closed loops."""
