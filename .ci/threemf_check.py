"""library.3mf read by lib3mf (the 3MF Consortium's reference implementation, from PyPI):
millimetres, one mesh object per piece of report.json named by its ID, every one manifold and
consistently oriented (watertight), one base material (colour) per part, and a build item per
object on the plates report.json lists.

Usage: python threemf_check.py OUT_DIR
"""

import json
import os
import sys

import lib3mf


def main(out):
    report = json.load(open(os.path.join(out, "report.json")))
    printing = report["printing"]
    pieces = {p["id"]: p for p in printing["pieces"]}
    wrapper = lib3mf.get_wrapper()
    model = wrapper.CreateModel()
    model.QueryReader("3mf").ReadFromFile(os.path.join(out, "library.3mf"))
    assert model.GetUnit() == lib3mf.ModelUnit.MilliMeter, model.GetUnit()
    names = []
    objects = model.GetMeshObjects()
    while objects.MoveNext():
        mesh = objects.GetCurrentMeshObject()
        name = mesh.GetName()
        assert mesh.IsManifoldAndOriented(), f"{name}: not watertight"
        assert mesh.GetTriangleCount() > 0, name
        names.append(name)
    assert sorted(names) == sorted(pieces), (sorted(names), sorted(pieces))
    materials = model.GetBaseMaterialGroups()
    assert materials.MoveNext(), "no base materials"
    group = materials.GetCurrentBaseMaterialGroup()
    parts = {p["name"] for p in printing["parts"]}
    assert group.GetCount() == len(parts), (group.GetCount(), parts)
    items = model.GetBuildItems()
    built = 0
    while items.MoveNext():
        built += 1
    assert built == len(pieces), (built, len(pieces))
    on_plates = sorted(i for p in printing["plates"] for i in p["pieces"])
    assert on_plates == sorted(pieces), "plates do not list every piece once"
    print(
        f"3mf: {len(names)} watertight pieces in mm, {group.GetCount()} colours, "
        f"{len(printing['plates'])} plates"
    )


if __name__ == "__main__":
    main(sys.argv[1])
