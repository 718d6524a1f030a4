"""pamsim muscles coupled to other simulators: :mod:`pamsim.coupling.mujoco` drives a MuJoCo model's
actuators with pamsim's pneumatic muscles (the optional extra ``pamsim[mujoco]``)."""
