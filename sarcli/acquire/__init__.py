"""GB-SAR acquisition: instrument drivers, the scan controller and a pseudo-terminal emulator.

Modules (one job each):

- :mod:`.port`        pyserial wrapper with deadlines, a private read buffer and disconnect mapping
- :mod:`.prologix`    Prologix GPIB-USB adapter (``++`` commands, host->instrument escaping, reads)
- :mod:`.vna8753`     :class:`Prologix8753`, the HP/Agilent 8753ES in native HP-IB mnemonics
- :mod:`.grbl`        :class:`GrblRail`, a single-axis GRBL 1.1 rail (unlock, home, moves, status)
- :mod:`.polswitch`   polarization switch interface (single polarization, GRBL pins, 11713A)
- :mod:`.config`      the acquisition TOML, validated before anything moves
- :mod:`.controller`  the stop-by-stop scan loop (append + flush per stop, resume, clean stops)
- :mod:`.emulator`    the emulated instruments on ``os.openpty`` pairs, with injectable faults

Units: the scan file and configuration are SI (m, Hz, s, dBm); GRBL speaks mm and mm/min, the
conversion happens only inside :class:`GrblRail`. Polarization names are TX letter then RX letter
("VH" = transmit V, receive H).
"""
