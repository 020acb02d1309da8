"""Reading and validating scene folders (transforms.json, images, labels)."""
