"""Issue 15: a catalogue of bad inputs and extreme admissible inputs."""
