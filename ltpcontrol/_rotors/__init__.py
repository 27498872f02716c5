"""Rotors and wind turbines: multi-blade coordinates, OpenFAST linearizations, Campbell diagrams."""
