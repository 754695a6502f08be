// Sums with discs on two axes (Roerdink-Minkowski Fig. 4-5, Theorem 5's bicircles R9-R11).
//   frep pov examples/roerdink/bidisc_sums.pov -O bidisc_sums_out.pov
//   povray +Ibidisc_sums_out.pov +Obidisc_sums.png +W640 +H360 +A
#version 3.7;
global_settings { assumed_gamma 1 }
camera { location <9, -13, 9> sky <0, 0, 1> up <0, 0, 1> right <-16/9, 0, 0> look_at <0, 0, 0.6> angle 36 }
light_source { <10, -12, 20> color rgb 1 }
light_source { <-12, -4, 8> color rgb 0.35 }
background { rgb <0.85, 0.9, 1> }
plane { z, -1.2 pigment { checker rgb 0.9 rgb 0.75 scale 1 } }
#declare Paint = texture { pigment { rgb <0.35, 0.55, 0.75> } finish { phong 0.4 } };

// Fig. 5: the xbidisc ydisc ⊕ zdisc = bicircle (a POV quartic) ∪ 2 cylinders.
object { $ ydisc(1) <+> zdisc(0.6) $ translate <-4, 0, 0.4> texture { Paint } }
// block ⊕ xdisc ⊕ ydisc: 8 bicircles, 16 cylinders, 4 blocks.
object { $ block(1.4, 1, 0.6, -0.7, -0.5, -0.3) <+> xdisc(0.5) <+> ydisc(0.35) $ translate <0, 0, 0.3>
         texture { Paint } }
// A plate rounded two ways: xline ⊕ yline ⊕ xdisc ⊕ zdisc.
object { $ xline(1.6) <+> yline(1.2) <+> xdisc(0.3) <+> zdisc(0.5) $ translate <3, -0.6, 0> texture { Paint } }
