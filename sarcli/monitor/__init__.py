"""GB-SAR monitoring: a campaign store updated scan by scan (temporal unwrapping, atmospheric phase
screen, displacement, velocity, acceleration), alarms with an inverse-velocity forecast, and a live
page. The manual is ``docs/monitoring.md``; the commands are ``sarcli gbsar monitor|series|serve``.

Modules: :mod:`.config` (the campaign TOML), :mod:`.engine` (one scan's update, pure arrays),
:mod:`.aps` (the atmospheric model fitted on stable points), :mod:`.unwrap` (temporal and spatial
unwrapping), :mod:`.kinematics` (velocity, acceleration, inverse-velocity forecast), :mod:`.alarms`
(levels with hysteresis, hooks), :mod:`.store` (crash-safe files), :mod:`.campaign` (scan -> image ->
update -> commit -> page), :mod:`.page` (the self-contained HTML), :mod:`.meteo`, :mod:`.serve`.
"""
