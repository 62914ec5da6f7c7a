"""Global relocalization: ``tf-global``, a turning-function place index resolved by ``tf-plus``."""
