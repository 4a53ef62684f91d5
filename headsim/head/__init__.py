"""A head as the procedures see it: the :class:`~headsim.head.interface.Head` interface,
its cameras' ROS ``CameraInfo`` (:mod:`headsim.head.camera_info`), MCAP recordings of it
(:mod:`headsim.head.mcap_log`) and a head replaying one (:mod:`headsim.head.replay`)."""
