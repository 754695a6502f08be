// a $ in a comment
/* and $ here */ #declare S = "$ not a term $";
object { $ sphere(1, 0, 0, 2) <+> xdisc(0.5) $ }
