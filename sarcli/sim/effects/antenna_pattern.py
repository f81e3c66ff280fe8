"""antenna_pattern: two-way amplitude gain sinc^2(L sin(psi)/lam) in azimuth and elevation.

psi_az, psi_el are the angles of the target direction off the boresight, measured in the antenna's
along-track and elevation planes (``sarcli.sim.pointing``). Without it the processed beam
(|sin psi_az| <= beam_extent * lam / L) is uniformly illuminated and every range is lit equally.
"""

from sarcli.sim.effects import no_parameters, switch

NAME = "antenna_pattern"
DOC = "sinc^2 two-way azimuth and elevation amplitude gain (else uniform inside the beam)"

parse = no_parameters
configure = switch("antenna_pattern")
