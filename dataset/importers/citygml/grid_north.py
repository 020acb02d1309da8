"""True north in a projected CRS: the meridian convergence, with pyproj.

A projected CRS's +y axis (grid north) points along true north only on its central
meridian; elsewhere the two differ by the *meridian convergence*. For UTM zone 32N
(EPSG:32632) at Ingolstadt (48.77 N, 11.4 E, 2.4 degrees east of the zone's 9 E meridian)
grid north lies 1.8 degrees clockwise of true north, so a facade whose normal points along
+y faces azimuth 1.8 degrees.
"""

from __future__ import annotations

STEP_M = 100.0
"""Length of the grid-north step whose geodesic azimuth is measured (the convergence changes
by well under 0.001 degrees over it)."""


def grid_north_deg(crs: str, x_m: float, y_m: float) -> float:
    """Clockwise angle (degrees, in (-180, 180]) from true north to the CRS's +y axis at
    (``x_m``, ``y_m``): the ``north_deg`` of :mod:`envelope.orientation`.

    Measured as the geodesic azimuth, on the CRS's own ellipsoid, of a step of
    :data:`STEP_M` along +y; the same as PROJ's meridian convergence, and it needs no
    convention for that angle's sign.

    Raises
    ------
    ValueError
        ``crs`` is unknown to PROJ or not projected.
    """
    import pyproj

    try:
        projected = pyproj.CRS.from_user_input(crs)
    except pyproj.exceptions.CRSError as exc:
        raise ValueError(f"CRS {crs!r} is unknown to PROJ ({exc}); give an EPSG code of a "
                         "projected CRS in metres") from exc
    if not projected.is_projected:
        raise ValueError(f"CRS {crs!r} is not projected: grid north needs map coordinates")
    to_geographic = pyproj.Transformer.from_crs(projected, projected.geodetic_crs,
                                                always_xy=True)
    lon0, lat0 = to_geographic.transform(x_m, y_m)
    lon1, lat1 = to_geographic.transform(x_m, y_m + STEP_M)
    azimuth = projected.get_geod().inv(lon0, lat0, lon1, lat1)[0]
    return float(-((-azimuth + 180.0) % 360.0 - 180.0)) + 0.0  # no -0.0
