"""Pure geometry: transforms, the head's kinematics, the camera model and the forward model."""
