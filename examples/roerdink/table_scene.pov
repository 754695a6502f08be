// Fig. 9's table, from the model: frep pov examples/roerdink/table.hf -O table.inc, then
//   povray +Iexamples/roerdink/table_scene.pov +Otable.png +W640 +H480 +A +L<dir of table.inc>
#version 3.7;
global_settings { assumed_gamma 1 }
#include "table.inc"
camera { location <3.2, -4.2, 2.4> sky <0, 0, 1> up <0, 0, 1> right <-4/3, 0, 0> look_at <0, 0, 0.35> angle 38 }
light_source { <4, -6, 8> color rgb 1 area_light <1, 0, 0>, <0, 1, 0>, 4, 4 }
light_source { <-5, -2, 4> color rgb 0.3 }
background { rgb <0.85, 0.9, 1> }
object { frep_model
  texture { pigment { wood color_map { [0 rgb <0.65, 0.42, 0.22>] [1 rgb <0.45, 0.27, 0.12>] } scale 0.08 rotate <0, 90, 20> }
            finish { phong 0.3 } } }
