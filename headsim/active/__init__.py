"""The active method: the image-only servos, the paper's procedures, search, calibration files."""
