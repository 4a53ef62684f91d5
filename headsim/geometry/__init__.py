"""Pure geometry: transforms, the head's kinematics, the camera model, the forward model
(``synthetic``, ``synthetic_neck``) and the random-target sampler."""
