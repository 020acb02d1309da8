"""CityGML LoD3 city models: reading, facades, context, the lod3 preset."""
