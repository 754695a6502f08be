object { $ block(1e308, 1, 1) <+> block(1e308, 1, 1) $ }
// and an erosion
object { $ block(1e308, 1, 1, -1e308, 0, 0) <-> sphere(1e308) $ }
