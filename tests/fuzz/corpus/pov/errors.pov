$ xline(1) <+> cone(2) $
