"""The baseline: Zhang-calibrated stereo (OpenCV) on the same rendered scenes."""
