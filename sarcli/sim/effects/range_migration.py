"""range_migration: the echo envelope follows the exact range R(t) (range cell migration).

Without it the envelope delay stays at the closest-approach range R0 of each target (no range
cell migration); the carrier phase exp(-j*4*pi*R(t)/lam) always follows the exact R(t), otherwise
there would be no synthetic aperture to simulate.
"""

from sarcli.sim.effects import no_parameters, switch

NAME = "range_migration"
DOC = "echo envelope follows the exact hyperbolic range (else frozen at closest approach)"

parse = no_parameters
configure = switch("range_migration")
