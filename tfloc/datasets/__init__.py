"""Where scans come from: the paper's perturbation protocol (``protocol``), simulated office floors
and scans (``offices``, ``noise``, ``synthetic``), the real logs (``real``) and ROS bags
(``from_bag``, ``interpolate``)."""
