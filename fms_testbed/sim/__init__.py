"""Simulation: JSBSim (sanitised model loading, trim, cached properties), the inner loops that run
inside it as a generated ``<system>``, their step-response analysis and the divergence checks."""
