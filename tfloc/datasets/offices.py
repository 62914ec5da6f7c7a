"""The three office maps of the benchmark, in the spirit of the paper's Figure 1 (metres).

A 20 × 15 m office floor: an east–west corridor (y 6.5–8.5 m) with a short north–south
corridor south of it, four rooms to the south and five to the north, 0.9 m doors, wall
columns and a few recesses. Three levels of environmental detail (Scenario I):

1. :func:`office_rooms` — rooms and corridors only (walls, columns, recesses);
2. :func:`office_furnished` — level 1 plus furniture (desks, cabinets, tables, shelves);
3. :func:`office_crowded` — level 2 plus clutter (chairs, boxes, bins, people).

All three are pure functions (no randomness), so the GeoJSON files are reproducible.
"""

from __future__ import annotations

import shapely
from shapely.geometry import LineString, Polygon, box

from tfloc.maps.vector import VectorMap

WIDTH, HEIGHT = 20.0, 15.0
CORRIDOR = (6.5, 8.5)  # y range of the east-west corridor
DOOR = 0.9  # door width (m)


def _wall(points: list[tuple[float, float]], doors: list[float] = ()) -> list[LineString]:
    """An axis-aligned polyline wall with ``DOOR``-wide gaps centred at the given positions
    (measured along the first segment's axis, which must be straight)."""
    (x0, y0), (_, y1) = points[0], points[-1]
    line = LineString(points)
    for c in doors:
        if abs(y1 - y0) < 1e-9:  # horizontal wall
            gap = box(c - DOOR / 2, y0 - 0.1, c + DOOR / 2, y0 + 0.1)
        else:
            gap = box(x0 - 0.1, c - DOOR / 2, x0 + 0.1, c + DOOR / 2)
        line = line.difference(gap)
    return [g for g in shapely.get_parts(line) if g.length > 1e-6]


def _outline() -> Polygon:
    """The building outline with two recesses (a stair core and an entrance niche)."""
    return Polygon([(0, 0), (20, 0), (20, 15), (14.0, 15), (14.0, 14.2), (12.0, 14.2), (12.0, 15),
                    (0, 15), (0, 8.5), (-0.6, 8.5), (-0.6, 6.5), (0, 6.5)])


def _columns() -> list[Polygon]:
    """Structural columns (0.4 m square) along the corridor walls and in the large rooms."""
    cols = []
    for x in (3.0, 7.0, 13.0, 17.0):
        cols.append(box(x - 0.2, CORRIDOR[0] - 0.4, x + 0.2, CORRIDOR[0]))
        cols.append(box(x - 0.2, CORRIDOR[1], x + 0.2, CORRIDOR[1] + 0.4))
    cols.append(box(4.3, 3.0, 4.7, 3.4))
    cols.append(box(15.3, 11.6, 15.7, 12.0))
    return cols


def _interior_walls() -> list[LineString]:
    """Corridor walls with doors, room partitions, the north-south corridor."""
    s, n = CORRIDOR
    walls: list[LineString] = []
    # South side of the corridor: rooms S1 (0-4.5), S2 (4.5-9), [N-S corridor 9-11], S3 (11-15.5), S4 (15.5-20).
    walls += _wall([(0, s), (9.0, s)], doors=[1.5, 6.0])
    walls += _wall([(11.0, s), (20.0, s)], doors=[14.0, 18.5])
    walls += _wall([(4.5, 0), (4.5, s)], doors=[1.2])  # S1|S2, with a connecting door
    walls += _wall([(9.0, 0), (9.0, s)], doors=[3.2])  # N-S corridor walls
    walls += _wall([(11.0, 0), (11.0, s)], doors=[4.8])
    walls += _wall([(15.5, 0), (15.5, s)])
    # North side: rooms N1 (0-5), N2 (5-8), N3 (8-12), N4 (12-16), N5 (16-20).
    walls += _wall([(0, n), (20.0, n)], doors=[2.5, 6.5, 9.0, 13.5, 18.0])
    walls += _wall([(5.0, n), (5.0, 15)])
    walls += _wall([(8.0, n), (8.0, 15)], doors=[13.0])
    walls += _wall([(12.0, n), (12.0, 14.2)])
    walls += _wall([(16.0, n), (16.0, 15)], doors=[10.5])
    # A kitchenette niche in N3 and a short partition in S4 (corners for the matchers).
    walls.append(LineString([(8.0, 12.0), (9.5, 12.0), (9.5, 12.8)]))
    walls.append(LineString([(17.5, 0), (17.5, 2.2), (18.4, 2.2)]))
    return walls


def _furniture() -> list[Polygon]:
    """Desks, cabinets, tables and shelves (level 2)."""
    return [
        # S1: two desks and a cabinet
        box(0.3, 0.4, 1.9, 1.2), box(2.4, 0.4, 4.0, 1.2), box(0.0, 4.0, 0.5, 5.6),
        # S2: meeting table and shelf
        box(5.8, 2.0, 7.8, 3.2), box(8.5, 0.3, 9.0, 1.9),
        # N-S corridor: printer
        box(10.4, 1.0, 11.0, 1.6),
        # S3: L-shaped desk and a cabinet
        Polygon([(11.4, 0.3), (13.8, 0.3), (13.8, 1.0), (12.1, 1.0), (12.1, 2.4), (11.4, 2.4)]),
        box(14.9, 4.0, 15.5, 5.8),
        # S4: desks
        box(16.0, 3.6, 17.4, 4.4), box(18.2, 3.6, 19.6, 4.4),
        # N1: desks back to back
        box(0.8, 11.0, 2.4, 12.4), box(2.6, 11.0, 4.2, 12.4),
        # N2: shelf along the wall
        box(5.0, 13.0, 5.5, 14.8),
        # N3: round table (octagon)
        shapely.Point(10.3, 10.6).buffer(0.6, quad_segs=2),
        # N4: desk and a sofa
        box(12.4, 13.2, 14.2, 13.9), box(14.0, 9.0, 15.6, 9.7),
        # N5: big table and cabinet
        box(17.2, 11.0, 19.0, 12.6), box(19.5, 13.0, 20.0, 14.6),
        # Corridor: a bench near the west end
        box(0.6, 8.1, 2.0, 8.5),
    ]


def _clutter() -> list[Polygon]:
    """Chairs, boxes, bins and people (level 3, "crowded")."""
    person = [(3.8, 7.5), (8.4, 7.2), (12.2, 7.8), (16.3, 7.3), (10.0, 3.8), (6.9, 12.9),
              (18.2, 9.9), (2.1, 3.0)]
    chairs = [(1.1, 1.6), (3.2, 1.6), (6.4, 3.7), (7.3, 1.6), (12.6, 1.5), (16.7, 4.9),
              (18.9, 4.9), (1.6, 10.6), (3.4, 12.8), (11.2, 10.1), (9.6, 11.0), (13.3, 12.8),
              (17.8, 10.6), (18.5, 13.0)]
    boxes = [box(5.2, 5.6, 5.8, 6.1), box(13.0, 5.7, 13.7, 6.2), box(19.3, 0.2, 19.8, 0.8),
             box(8.3, 14.3, 9.0, 14.8), box(0.1, 14.1, 0.8, 14.8), box(14.6, 6.9, 15.1, 7.3)]
    geoms = [shapely.Point(x, y).buffer(0.25, quad_segs=2) for x, y in person]
    geoms += [box(x - 0.22, y - 0.22, x + 0.22, y + 0.22) for x, y in chairs]
    return geoms + boxes


def office_rooms() -> VectorMap:
    """Level 1: rooms and corridors only."""
    return VectorMap(walls=tuple(_interior_walls()), obstacles=tuple(_columns()),
                     outline=_outline(), name="office-1")


def office_furnished() -> VectorMap:
    """Level 2: rooms, corridors and furniture."""
    return VectorMap(walls=tuple(_interior_walls()), obstacles=tuple(_columns() + _furniture()),
                     outline=_outline(), name="office-2")


def office_crowded() -> VectorMap:
    """Level 3: furnished and crowded (chairs, boxes, people)."""
    return VectorMap(walls=tuple(_interior_walls()),
                     obstacles=tuple(_columns() + _furniture() + _clutter()),
                     outline=_outline(), name="office-3")


OFFICES = {1: office_rooms, 2: office_furnished, 3: office_crowded}
