"""sarcli: reproducible SAR processing from raw echoes and GB-SAR scans to products."""

__version__ = "0.1.0"
