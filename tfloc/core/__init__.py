"""The shared core: poses, the laser, the map protocol, the problem every matcher answers, the
matcher protocol and registry, and matcher parameters. Imports nothing else of tfloc."""
