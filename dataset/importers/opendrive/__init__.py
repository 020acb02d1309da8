"""OpenDRIVE road networks: the streets a street capture drives along."""
