"""File formats: HDF5 products, GeoTIFF/PNG images, CEOS RAW and MATLAB blocks."""
