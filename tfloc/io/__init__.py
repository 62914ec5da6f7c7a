"""File formats at the edges: maps (``geojson``, ``rosmap``, ``maps.load_map``), scenario datasets
(``scenario``), results (``estimates``), CARMEN logs and relations, ROS bags, TUM trajectories; all
text read through ``text``."""
