"""The semantic neural SDF: encodings, the fields, the normalised frame, checkpoints and the
trained field seen in world metres."""
