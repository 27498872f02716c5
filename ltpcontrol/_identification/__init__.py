"""Identification: excitation design, HTF estimation, subspace identification and refinement."""
