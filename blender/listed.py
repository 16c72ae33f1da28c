"""The panels' editable lists (stopmo seeds, loa bone sets): removing an item by index."""


def remove_item(op, items, index, what):
    """Removes item `index` (-1: the last) of the collection property `items`; a bad index is
    reported in one line by operator `op`. Returns the operator's result."""
    i = index if index >= 0 else len(items) - 1
    if not 0 <= i < len(items):
        op.report({"ERROR"}, f"{what}: no item {index} ({len(items)} in the list)")
        return {"CANCELLED"}
    items.remove(i)
    return {"FINISHED"}
