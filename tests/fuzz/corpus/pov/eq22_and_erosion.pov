#version 3.7;
// eq. 22
object { $ xline(5) <+> zline(5) <+> yline(100) <+> ydisc(2) $ }
object { $ block(4, 4, 4, -2, -2, -2) <-> sphere(0.5) $ }
