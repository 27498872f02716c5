"""Periodic systems with delays: state-delay LTP systems, delay elements, PDDE monodromy, stability charts."""
