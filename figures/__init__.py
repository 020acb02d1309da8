"""The paper's figures, made only from files that metrics/ and dataset/ wrote."""
