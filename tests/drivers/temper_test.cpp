// Placeholder: tests arrive with the codec.
