"""The head and scene MJCF files: package data, installed as ``headsim.models``."""
