"""A catalogue of bad inputs and extreme admissible inputs."""
