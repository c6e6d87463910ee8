"""Zohdi 2014: electrically aided sintering on the engine (see dem/zohdi/simulation.py)."""
