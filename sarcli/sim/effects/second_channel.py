"""second_channel: one transmitter, a second receiver ``receiver_offset_m`` ahead along track (ATI).

Channel 0 receives at the transmitter; channel 1 at r_tx + d * x_a (x_a the antenna along-track
axis). Each channel's phase and delay use the bistatic mean range (R_tx + R_rx)/2 (stop-and-hop);
both channels share the transmitter's antenna gain. Stored in /echo_channels with
radar.receiver_offsets_m = (0, d).
"""

from dataclasses import dataclass

from sarcli.errors import ConfigError

NAME = "second_channel"
DOC = "second receiver d metres along track, bistatic (R_tx + R_rx)/2 per channel"


@dataclass(frozen=True)
class Options:
    """receiver_offset_m: along-track position of receiver 1 relative to the transmitter (m), non-zero."""

    receiver_offset_m: float


def parse(options, platform):
    if options is None:
        raise ConfigError("effect second_channel needs a table [second_channel] with receiver_offset_m")
    if options.receiver_offset_m == 0:
        raise ConfigError("second_channel.receiver_offset_m: must be non-zero")
    return options.receiver_offset_m


def configure(ctx, params):
    ctx.receiver_offsets_m = (0.0, params)
