"""Chord-length (RCA) reparametrization of B-spline surfaces within a
guaranteed tolerance (Hamann, Jean, Razdan, handbook ch. 29, §29.2)."""
