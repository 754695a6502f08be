// Roerdink-Minkowski's example sums as a POV-Ray scene with $ ... $ Minkowski terms.
//   frep pov examples/roerdink/paper_sums.pov -O paper_sums_out.pov
//   povray +Ipaper_sums_out.pov +Opaper_sums.png +W640 +H360 +A
#version 3.7;
global_settings { assumed_gamma 1 }
camera { location <9, -13, 9> sky <0, 0, 1> up <0, 0, 1> right <-16/9, 0, 0> look_at <0, 0, 0.6> angle 40 }
light_source { <10, -12, 20> color rgb 1 }
light_source { <-12, -4, 8> color rgb 0.35 }
background { rgb <0.85, 0.9, 1> }
plane { z, -0.8 pigment { checker rgb 0.9 rgb 0.75 scale 1 } }
#declare Paint = texture { pigment { rgb <0.75, 0.45, 0.3> } finish { phong 0.4 } };

// Fig. 3: a discus, xdisc ⊕ sphere = torus ∪ cylinder.
object { $ xdisc(1) <+> sphere(0.4) $ translate <-5, 0, 0.6> texture { Paint } }
// Fig. 6: block ⊕ zdisc = 2 blocks ∪ 4 cylinders.
object { $ block(1.5, 1, 1, -0.75, -0.5, -0.5) <+> zdisc(0.5) $ translate <-1.8, 0, 0.2> texture { Paint } }
// §IV.D: block ⊕ zdisc ⊕ sphere (8 tori, 16 cylinders, 4 blocks).
object { $ xline(1.2) <+> yline(1) <+> zline(0.8) <+> zdisc(0.4) <+> sphere(0.3) $
         translate <1, -0.5, -0.2> texture { Paint } }
// Eq. 22: xline(5) <+> zline(5) <+> yline(100) <+> ydisc(2), scaled down (and cut to y <= 12).
object { $ xline(5) <+> zline(5) <+> yline(100) <+> ydisc(2) $ scale 0.2 translate <4.5, -1, -0.5>
         clipped_by { plane { y, 1.6 } } texture { Paint } }
