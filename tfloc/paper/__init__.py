"""The paper's method, as written (matcher ``tf``): ShortStraw corners (Algs. 1–3, ``corners``),
turning functions and their matching (Alg. 4, Sec. 4.3, Eq. 13, ``turning``) and the Nelder–Mead
pose search (Alg. 5, ``matcher``)."""
