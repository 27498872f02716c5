"""Analysis and design on LTP models: Lyapunov and Riccati equations, norms, zeros, controllers, reduction."""
