"""Numbers of the Sentinel-1 SAR space packet format, from the specification.

Source: Airbus DS, *Sentinel-1 SAR Space Packet Protocol Data Unit*, S1-IF-ASD-PL-0007 issue 13
(2015), cited as ``[S1-ISP, §...]``. Section and table numbers refer to that issue. Every table
here is transcribed from it; where the document contradicts itself the choice is noted.
"""

from __future__ import annotations

#: Reference frequency of the instrument clock [S1-ISP, §3.2.5.4]: 37.53472224 MHz.
F_REF_HZ = 37.53472224e6
#: Packet primary header (6 octets) and secondary header (62 octets) lengths [S1-ISP, §3.1, §3.2].
PRIMARY_HEADER_BYTES = 6
SECONDARY_HEADER_BYTES = 62
HEADER_BYTES = PRIMARY_HEADER_BYTES + SECONDARY_HEADER_BYTES
#: Sync marker of the fixed ancillary data field [S1-ISP, §3.2.2.1].
SYNC_MARKER = 0x352EF853
#: GPS time origin of the coarse/fine datation [S1-ISP, §3.2.1.1] (no leap seconds in GPS time).
GPS_EPOCH = "1980-01-06T00:00:00"
#: BAQ block: 128 codes per channel section (256 complex samples) [S1-ISP, §4.3].
BLOCK_CODES = 128
#: Decimation-filter transient suppressed at the start of the sampling window: 320 / (8 f_ref)
#: [S1-ISP, §3.2.5.11].
DELTA_T_SUPPR_S = 320.0 / (8.0 * F_REF_HZ)

# BAQ mode codes [S1-ISP, §3.2.5.2].
BAQ_BYPASS = 0
BAQ_MODES = (3, 4, 5)
FDBAQ_MODES = (12, 13, 14)
#: Test-mode codes for which the data are bypass (format A) [S1-ISP, Table 3.3-2].
TEST_MODES_BYPASS = (5, 7)
TEST_MODES_OPERATIONAL = (0, 4, 6)

# Signal types [S1-ISP, §3.2.5.14.3].
SIGNAL_ECHO = 0
SIGNAL_NOISE = 1
SIGNAL_NAMES = {0: "echo", 1: "noise", 8: "tx_cal", 9: "rx_cal", 10: "epdn_cal", 11: "ta_cal",
                12: "apdn_cal", 15: "txh_cal_iso"}

#: Polarisation code -> (Tx, Rx for Rx channel 0 (V), Rx for channel 1 (H)) [S1-ISP, §3.2.5.13.1.1,
#: §3.2.2.5]: the Rx channel ID fixes the receive polarisation (0 = V, 1 = H).
TX_POLARISATION = {0: "H", 1: "H", 2: "H", 3: "H", 4: "V", 5: "V", 6: "V", 7: "V"}
RX_CHANNEL_POLARISATION = {0: "V", 1: "H"}

#: Range decimation filters [S1-ISP, §3.2.5.4]: code -> (L, M, filter length NF, swath names); the
#: sampling rate after decimation is f_dec = (L/M) * 4 f_ref. Code 2 is not applicable.
RANGE_DECIMATION = {
    0: (3, 4, 28, ("FULL",)),
    1: (2, 3, 28, ("S1", "WV1")),
    3: (5, 9, 32, ("S2",)),
    4: (4, 9, 40, ("S3",)),
    5: (3, 8, 48, ("S4",)),
    6: (1, 3, 52, ("S5",)),
    7: (1, 6, 92, ("EW1",)),
    8: (3, 7, 36, ("IW1",)),
    9: (5, 16, 68, ("S6", "IW3")),
    10: (3, 26, 120, ("EW2", "EW3", "EW4", "EW5")),
    11: (4, 11, 44, ("IW2", "WV2")),
}

#: Filter output offsets [S1-ISP, Table 5.1-2] (= 80 + NF/4).
FILTER_OUTPUT_OFFSET = {0: 87, 1: 87, 3: 88, 4: 90, 5: 92, 6: 93, 7: 103, 8: 89, 9: 97, 10: 110, 11: 91}

#: Values D as a function of C for each filter [S1-ISP, Table 5.1-1] (the number of samples after
#: decimation, §3.2.5.12).
D_TABLE = {
    0: (1, 1, 2, 3),
    1: (1, 1, 2),
    3: (1, 1, 2, 2, 3, 3, 4, 4, 5),
    4: (0, 1, 1, 2, 2, 3, 3, 4, 4),
    5: (0, 1, 1, 1, 2, 2, 3, 3),
    6: (0, 0, 1),
    7: (0, 0, 0, 0, 0, 1),
    8: (0, 1, 1, 2, 2, 3, 3),
    9: (0, 0, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5),
    10: (0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 3, 3),
    11: (0, 1, 1, 1, 2, 2, 3, 3, 3, 4, 4),
}

#: ECC programme number -> measurement mode [S1-ISP, Table 3.2-4] (the swath family for naming).
ECC_MODES = {
    1: "S1", 2: "S2", 3: "S3", 4: "S4", 5: "S5", 6: "S6", 8: "IW", 9: "WV", 10: "S5",
    11: "S1", 12: "S2", 13: "S3", 14: "S4", 15: "RFC", 16: "TEST", 17: "S3", 18: "S1", 19: "S2",
    20: "S3", 21: "S4", 22: "S5", 23: "S5", 24: "S6", 25: "S5", 26: "S5", 27: "S6", 31: "S3",
    32: "EW", 33: "S1", 34: "S3", 35: "S6", 37: "S1", 38: "S2", 39: "S3", 40: "S4", 41: "S5",
    42: "S5", 43: "S6", 44: "EW", 45: "IW", 46: "WV",
}
#: Modes whose echoes come in bursts (TOPS) or vignettes: not a continuous stripmap.
BURST_MODES = ("IW", "EW")

# ---------------------------------------------------------------------------------------------
# Sample reconstruction [S1-ISP, §4.3, §4.4, §5.2].

#: Number of magnitude codes k per FDBAQ bit-rate code BRC 0..4 [S1-ISP, Figs. 4-7..4-11].
BRC_LEVELS = (4, 5, 7, 10, 16)

#: Huffman codes of the magnitude (after the sign bit) per BRC [S1-ISP, Figs. 4-7..4-11], as bit
#: strings indexed by MCode. Each tree is a prefix code.
HUFFMAN_CODES: tuple[tuple[str, ...], ...] = (
    ("0", "10", "110", "111"),
    ("0", "10", "110", "1110", "1111"),
    ("0", "10", "110", "1110", "11110", "111110", "111111"),
    ("00", "01", "10", "110", "1110", "11110", "111110", "1111110", "11111110", "11111111"),
    ("00", "010", "011", "100", "101", "1100", "1101", "1110", "11110", "111110", "11111100",
     "11111101", "111111100", "111111101", "111111110", "111111111"),
)

#: Simple reconstruction parameters [S1-ISP, Table 5.2-1]: the value of the largest MCode, by THIDX
#: (index), for BAQ 3/4/5 bit (A3, A4, A5) and FDBAQ BRC 0..4 (B0..B4). The table's length fixes the
#: THIDX range of simple reconstruction (THIDX <= len - 1), as in the reconstruction laws of §4.3/§4.4.
#: Note: example 3 of §4.4 quotes B3(THIDX=5) = 9.48; the table of document issue 13 (which the change
#: record says was modified in document issue 12) gives 9.50, used here.
SIMPLE_A = {
    3: (3.00, 3.00, 3.12, 3.55),
    4: (7.00, 7.00, 7.00, 7.17, 7.40, 7.76),
    5: (15.00, 15.00, 15.00, 15.00, 15.00, 15.00, 15.44, 15.56, 16.11, 16.38, 16.65),
}
SIMPLE_B = (
    (3.00, 3.00, 3.16, 3.53),
    (4.00, 4.00, 4.08, 4.37),
    (6.00, 6.00, 6.00, 6.15, 6.50, 6.88),
    (9.00, 9.00, 9.00, 9.00, 9.36, 9.50, 10.10),
    (15.00, 15.00, 15.00, 15.00, 15.00, 15.00, 15.22, 15.50, 16.05),
)

#: Normalised reconstruction levels [S1-ISP, Table 5.2-2], by MCode.
NRL_BAQ = {
    3: (0.2490, 0.7681, 1.3655, 2.1864),
    4: (0.1290, 0.3900, 0.6601, 0.9471, 1.2623, 1.6261, 2.0793, 2.7467),
    5: (0.0660, 0.1985, 0.3320, 0.4677, 0.6061, 0.7487, 0.8964, 1.0510, 1.2143, 1.3896, 1.5800,
        1.7914, 2.0329, 2.3234, 2.6971, 3.2692),
}
NRL_FDBAQ = (
    (0.3637, 1.0915, 1.8208, 2.6406),
    (0.3042, 0.9127, 1.5216, 2.1313, 2.8426),
    (0.2305, 0.6916, 1.1528, 1.6140, 2.0754, 2.5369, 3.1191),
    (0.1702, 0.5107, 0.8511, 1.1916, 1.5321, 1.8726, 2.2131, 2.5536, 2.8942, 3.3744),
    (0.1130, 0.3389, 0.5649, 0.7908, 1.0167, 1.2428, 1.4687, 1.6947, 1.9206, 2.1466, 2.3725,
     2.5985, 2.8244, 3.0504, 3.2764, 3.6623),
)

#: Sigma factors by THIDX 0..255 [S1-ISP, Table 5.2-3].
SIGMA_FACTORS = (
    0.00, 0.63, 1.25, 1.88, 2.51, 3.13, 3.76, 4.39, 5.01, 5.64, 6.27, 6.89, 7.52, 8.15, 8.77, 9.40,
    10.03, 10.65, 11.28, 11.91, 12.53, 13.16, 13.79, 14.41, 15.04, 15.67, 16.29, 16.92, 17.55, 18.17,
    18.80, 19.43, 20.05, 20.68, 21.31, 21.93, 22.56, 23.19, 23.81, 24.44, 25.07, 25.69, 26.32, 26.95,
    27.57, 28.20, 28.83, 29.45, 30.08, 30.71, 31.33, 31.96, 32.59, 33.21, 33.84, 34.47, 35.09, 35.72,
    36.35, 36.97, 37.60, 38.23, 38.85, 39.48, 40.11, 40.73, 41.36, 41.99, 42.61, 43.24, 43.87, 44.49,
    45.12, 45.75, 46.37, 47.00, 47.63, 48.25, 48.88, 49.51, 50.13, 50.76, 51.39, 52.01, 52.64, 53.27,
    53.89, 54.52, 55.15, 55.77, 56.40, 57.03, 57.65, 58.28, 58.91, 59.53, 60.16, 60.79, 61.41, 62.04,
    62.98, 64.24, 65.49, 66.74, 68.00, 69.25, 70.50, 71.76, 73.01, 74.26, 75.52, 76.77, 78.02, 79.28,
    80.53, 81.78, 83.04, 84.29, 85.54, 86.80, 88.05, 89.30, 90.56, 91.81, 93.06, 94.32, 95.57, 96.82,
    98.08, 99.33, 100.58, 101.84, 103.09, 104.34, 105.60, 106.85, 108.10, 109.35, 110.61, 111.86,
    113.11, 114.37, 115.62, 116.87, 118.13, 119.38, 120.63, 121.89, 123.14, 124.39, 125.65, 126.90,
    128.15, 129.41, 130.66, 131.91, 133.17, 134.42, 135.67, 136.93, 138.18, 139.43, 140.69, 141.94,
    143.19, 144.45, 145.70, 146.95, 148.21, 149.46, 150.71, 151.97, 153.22, 154.47, 155.73, 156.98,
    158.23, 159.49, 160.74, 161.99, 163.25, 164.50, 165.75, 167.01, 168.26, 169.51, 170.77, 172.02,
    173.27, 174.53, 175.78, 177.03, 178.29, 179.54, 180.79, 182.05, 183.30, 184.55, 185.81, 187.06,
    188.31, 189.57, 190.82, 192.07, 193.33, 194.58, 195.83, 197.09, 198.34, 199.59, 200.85, 202.10,
    203.35, 204.61, 205.86, 207.11, 208.37, 209.62, 210.87, 212.13, 213.38, 214.63, 215.89, 217.14,
    218.39, 219.65, 220.90, 222.15, 223.41, 224.66, 225.91, 227.17, 228.42, 229.67, 230.93, 232.18,
    233.43, 234.69, 235.94, 237.19, 238.45, 239.70, 240.95, 242.21, 243.46, 244.71, 245.97, 247.22,
    248.47, 249.73, 250.98, 252.23, 253.49, 254.74, 255.99, 255.99,
)

