"""Emulation of [KimAODCCD]'s acousto-optic (AOD) / CCD real-time SAR processor.

``devices`` holds the device parameters (defaults from [KimAODCCD, §2.5]) and derives the processor's design from
the radar geometry; ``limitations`` is the registry of device limitations (each one effect the user
can switch on); ``emulator`` runs the signal chain; ``compare`` measures it against the digital RD image.
"""
