"""target_motion: targets move with their given ground velocity.

Linear scenes: vx_mps (cross-track, x) and vy_mps (along-track, y) in the LOCAL frame; orbit scenes:
v_east_mps, v_north_mps, v_up_mps at the target. The listed position is the position at the
target's reference time (its azimuth_time_s for slant-placed targets, else the scene centre).
Without this effect the velocities in the file are ignored (static scene).
"""

from sarcli.sim.effects import no_parameters, switch

NAME = "target_motion"
DOC = "targets move with their given velocity (else static)"

parse = no_parameters
configure = switch("target_motion")
