"""Feature detection in rendered images: markers, cross points, chessboard corners."""
