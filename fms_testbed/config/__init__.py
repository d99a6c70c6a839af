"""Configuration schemas (pydantic): aircraft files, scenario files, procedure blocks, navigation
blocks. Validation errors are one line naming the file and field."""
