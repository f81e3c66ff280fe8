"""second_channel: one transmitter, a second receiver ``receiver_offset_m`` ahead along track (ATI).

Channel 0 receives at the transmitter; channel 1 at r_tx + d * x_a (x_a the antenna along-track
axis). Each channel's phase and delay use the bistatic mean range (R_tx + R_rx)/2 (stop-and-hop);
both channels share the transmitter's antenna gain. Stored in /echo_channels with
radar.receiver_offsets_m = (0, d).
"""

from sarcli.errors import FormatError

NAME = "second_channel"
DOC = "second receiver d metres along track, bistatic (R_tx + R_rx)/2 per channel"


def parse(table, platform):
    if table is None:
        raise FormatError("effect second_channel needs a table [second_channel] with receiver_offset_m")
    d = table.num("receiver_offset_m")
    if d == 0:
        raise table.err("receiver_offset_m", "must be non-zero")
    return d


def configure(ctx, params):
    ctx.receiver_offsets_m = (0.0, params)
