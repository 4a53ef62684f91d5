"""The scenario files: package data, installed as ``headsim.scenarios``."""
