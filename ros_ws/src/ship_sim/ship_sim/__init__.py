"""Vessel plant models (Mariner, Esso tanker, container ship, Nomoto, NPS AUV II), ocean current,
and the vessel simulator node."""
