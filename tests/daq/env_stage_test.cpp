// Placeholder: tests arrive with the stage.
