// Sums with discs on three axes, or on two with a sphere (Roerdink-Minkowski Theorem 5's
// R12-R16, §IV.F's B*): blocks and cylinders as POV primitives, the tridiscsphere corner pieces
// as mesh2 polygonised from the exact convex-projection field (docs/pov.md).
//   frep pov examples/roerdink/tricircle_sums.pov -O tricircle_sums_out.pov
//   povray +Itricircle_sums_out.pov +Otricircle_sums.png +W640 +H360 +A
#version 3.7;
global_settings { assumed_gamma 1 }
camera { location <9, -13, 9> sky <0, 0, 1> up <0, 0, 1> right <-16/9, 0, 0> look_at <0, 0, 0.6> angle 36 }
light_source { <10, -12, 20> color rgb 1 }
light_source { <-12, -4, 8> color rgb 0.35 }
background { rgb <0.85, 0.9, 1> }
plane { z, -1.2 pigment { checker rgb 0.9 rgb 0.75 scale 1 } }
#declare Paint = texture { pigment { rgb <0.75, 0.5, 0.3> } finish { phong 0.4 } };

// The hull of a bicircle-sphere: xdisc ⊕ ydisc ⊕ sphere (one tridiscsphere).
object { $ xdisc(0.8) <+> ydisc(0.5) <+> sphere(0.25) $ translate <-4, 0, 0.4> texture { Paint } }
// B* (eq. 18): block ⊕ xdisc ⊕ ydisc ⊕ zdisc ⊕ sphere: 6 blocks, 12 cylinders, 8 tridiscspheres.
object { $ block(1.4, 1, 0.6, -0.7, -0.5, -0.3) <+> xdisc(0.35) <+> ydisc(0.3) <+> zdisc(0.4) <+> sphere(0.1) $
         translate <0, 0, 0.3> texture { Paint } }
// A tricircle's hull (no sphere): xdisc ⊕ ydisc ⊕ zdisc.
object { $ xdisc(0.7) <+> ydisc(0.6) <+> zdisc(0.5) $ translate <3.6, -0.6, 0> texture { Paint } }
