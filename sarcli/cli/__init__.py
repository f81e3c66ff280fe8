"""The sarcli command line (Typer). Commands only parse, call library code and report."""
