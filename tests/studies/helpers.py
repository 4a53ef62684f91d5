"""A calibration and a chessboard job's results as ``headsim reproduce`` reads them."""

from __future__ import annotations

CALIBRATION = {
    "head_hash": "ab" * 32,
    "block": {
        "alpha_e_rad": [0.05790, -0.02530],
        "alpha_e_std_rad": [2e-4, 2e-4],
        "fixated": 11,
        "targets": 12,
        "render_counts": {"images": 5, "windows": 50, "retakes": 0, "previews": 20, "total": 75},
    },
}


BOARD = {
    "results": {
        "experiment": {
            "side_mean_m": 0.03003,
            "side_std_m": 0.0004,
            "corners": 6,
            "corners_measured": 6,
            "widths_m": [0.0300],
            "heights_m": [0.0301],
        }
    }
}
