"""Readers and writers at the edges: GeoJSON maps, scenario datasets (CARMEN logs, ROS maps later)."""
