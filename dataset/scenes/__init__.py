"""Scene folders: reading and writing ``transforms.json``, images and label masks, validation,
and rendering a building into a scene folder."""
