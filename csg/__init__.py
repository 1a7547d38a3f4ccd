"""csg: solids, booleans and transforms on top of the implicitvox kernel (in progress)."""

__all__: list[str] = []
