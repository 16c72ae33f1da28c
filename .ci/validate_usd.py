#!/usr/bin/env python3
"""Validates every `*.usda`, `*.usdc` and `*.usdz` in DIR with Pixar's USD (`pip install usd-core`).

Usage: python3 .ci/validate_usd.py DIR

Per layer:
1. `Usd.Stage.Open` must succeed with no composition error and no diagnostic (parse warnings
   and errors are captured with UsdUtils.CoalescingDiagnosticDelegate).
2. Pixar's compliance rules: `UsdUtils.ComplianceChecker` when the installed usd-core still
   has it (≤ 25.x); newer releases (26.x) replaced it by the UsdValidation framework that
   `usdchecker` runs, so every registered validator runs instead. Errors are failures;
   warnings are printed. Skipped, because they only concern `.usdz` packages (byte alignment,
   compression, files inside a package) and never apply to a plain `.usda`/`.usdc` layer: the
   usdz package rules listed in USDZ_ONLY (they do run on `.usdz` packages).
3. Geometry, for every UsdGeom.Mesh at every authored time code (or the default time):
   max(faceVertexIndices) + 1 <= len(points), sum(faceVertexCounts) == len(faceVertexIndices),
   every face count >= 3, UsdGeom.Mesh.ValidateTopology, finite points, an extent of two
   corners that contains every point, and vertex-interpolated primvars with one value per
   point; `velocities` one per point, finite, and (fixed topology) equal to the points'
   central difference per second.
   Every UsdGeom.BasisCurves likewise: linear, sum(curveVertexCounts) == len(points), every
   curve >= 2 points, widths and vertex primvars one per point, finite points in the extent.
Tested with usd-core 24.11 (ComplianceChecker) and 26.11 (UsdValidation).
Prints one line per failure, then "USD validation: N passed, M failed"; exits 1 on any failure
(and 1 when DIR holds no USD file at all, so a broken test setup cannot pass silently).
"""

import pathlib
import sys

from pxr import Usd, UsdGeom, UsdUtils, Sdf

# Validators / compliance rules that only apply to .usdz packages.
USDZ_ONLY = {
    "usdUtilsValidators:RootPackageValidator",
    "usdUtilsValidators:UsdzPackageValidator",
    "usdUtilsValidators:PackageEncapsulationValidator",
    "usdUtilsValidators:FileExtensionValidator",
    "ByteAlignmentChecker",
    "CompressionChecker",
}


def compliance(path):
    """Errors of Pixar's compliance rules (list of strings); warnings are printed."""
    skipped = set() if path.suffix == ".usdz" else USDZ_ONLY
    checker_class = getattr(UsdUtils, "ComplianceChecker", None)
    errors = []
    if checker_class is not None:
        checker = checker_class(arkit=False, skipARKitRootLayerCheck=False, rootPackageOnly=False,
                                skipVariants=False, verbose=False)
        checker.CheckCompliance(str(path))
        errors += [e for e in checker.GetErrors()
                   if not any(r in e for r in skipped)]
        failed = [f for f in checker.GetFailedChecks() if not any(r in f for r in skipped)]
        errors += [f"failed check: {f}" for f in failed]
        for w in checker.GetWarnings():
            print(f"{path.name}: warning: {w}")
        return errors
    from pxr import UsdValidation

    registry = UsdValidation.ValidationRegistry()
    validators = [v for v in registry.GetOrLoadAllValidators()
                  if v.GetMetadata().name not in skipped]
    stage = Usd.Stage.Open(str(path))
    context = UsdValidation.ValidationContext(validators)
    for e in context.Validate(stage):
        if e.HasNoError():
            continue
        line = f"{e.GetValidator().GetMetadata().name}: {e.GetMessage()}"
        if e.GetType() == UsdValidation.ValidationErrorType.Error:
            errors.append(line)
        else:
            print(f"{path.name}: {e.GetType()}: {line}")
    return errors


def time_codes(mesh):
    """Every authored time code of the mesh's attributes, or [Default] for static data."""
    times = set()
    for attr in mesh.GetPrim().GetAttributes():
        times.update(attr.GetTimeSamples())
    return sorted(times) if times else [Usd.TimeCode.Default()]


def check_points(geom, primvars, tc, at, points):
    """Failures of a point-based prim at one time code: finite points inside an extent of two
    corners, vertex-interpolated primvars with one value per point."""
    out = []
    text = str(points).lower()  # formatted in C++: fast even for large arrays
    if "nan" in text or "inf" in text:
        out.append(f"{at}: non-finite point")
    extent = geom.GetExtentAttr().Get(tc)
    if extent is None or len(extent) != 2:
        out.append(f"{at}: extent missing or not two corners")
    elif len(points):
        lo, hi = extent
        # The points' own bounding box (computed by USD), then containment per axis.
        plo, phi = UsdGeom.PointBased.ComputeExtent(points)
        if any(plo[k] < lo[k] or phi[k] > hi[k] for k in range(3)):
            out.append(f"{at}: points span {tuple(plo)}..{tuple(phi)}, outside extent "
                       f"{tuple(lo)}..{tuple(hi)}")
    for pv in primvars:
        if pv.GetInterpolation() != UsdGeom.Tokens.vertex or not pv.HasValue():
            continue
        value = pv.Get(tc)
        if value is not None and len(value) != len(points):
            out.append(f"{at}: primvar {pv.GetPrimvarName()} has {len(value)} values for "
                       f"{len(points)} points")
    return out


def check_mesh(mesh):
    """Failures (strings) of one mesh over all its time codes."""
    out = []
    where = str(mesh.GetPath())
    primvars = UsdGeom.PrimvarsAPI(mesh).GetPrimvars()
    for t in time_codes(mesh):
        tc = Usd.TimeCode(t) if not isinstance(t, Usd.TimeCode) else t
        at = f"{where} @ {'default' if tc.IsDefault() else t}"
        points = mesh.GetPointsAttr().Get(tc) or []
        counts = mesh.GetFaceVertexCountsAttr().Get(tc) or []
        indices = mesh.GetFaceVertexIndicesAttr().Get(tc) or []
        if sum(counts) != len(indices):
            out.append(f"{at}: sum(faceVertexCounts) = {sum(counts)} != "
                       f"len(faceVertexIndices) = {len(indices)}")
        if any(c < 3 for c in counts):
            out.append(f"{at}: a face has fewer than 3 vertices")
        if len(indices) and max(indices) + 1 > len(points):
            out.append(f"{at}: max index + 1 = {max(indices) + 1} > {len(points)} points")
        if len(indices) and min(indices) < 0:
            out.append(f"{at}: negative face vertex index")
        ok, why = UsdGeom.Mesh.ValidateTopology(indices, counts, len(points))
        if not ok:
            out.append(f"{at}: ValidateTopology: {why}")
        out += check_points(mesh, primvars, tc, at, points)
    out += check_velocities(mesh, where)
    if mesh.GetSubdivisionSchemeAttr().Get() != UsdGeom.Tokens.none:
        out.append(f"{where}: subdivisionScheme is not \"none\"")
    return out


def check_velocities(geom, where):
    """Failures of `velocities`: one vector per point at every time code that has points, and
    consistent with the motion (v ≈ (p(t+1) − p(t−1)) / 2 × timeCodesPerSecond inside)."""
    out = []
    attr = geom.GetVelocitiesAttr()
    if not attr.HasAuthoredValue():
        return out
    stage = geom.GetPrim().GetStage()
    fps = stage.GetTimeCodesPerSecond()
    times = attr.GetTimeSamples()
    for t in times:
        points = geom.GetPointsAttr().Get(t) or []
        v = attr.Get(t) or []
        if len(v) != len(points):
            out.append(f"{where} @ {t}: {len(v)} velocities for {len(points)} points")
        text = str(v).lower()
        if "nan" in text or "inf" in text:
            out.append(f"{where} @ {t}: non-finite velocity")
    if geom.GetPrim().IsA(UsdGeom.Mesh) and \
            UsdGeom.Mesh(geom).GetFaceVertexIndicesAttr().GetNumTimeSamples() > 0:
        # A topology that changes per frame (a subdivided smear): point i is not the same
        # vertex from frame to frame, so there is no central difference to compare with
        # (the Rust tests compare such velocities with the point cache's at the input's
        # vertices).
        return out
    for t in times[1:-1]:
        before, after = geom.GetPointsAttr().Get(t - 1), geom.GetPointsAttr().Get(t + 1)
        v = attr.Get(t)
        if before is None or after is None or len(before) != len(v) or len(after) != len(v):
            continue
        for i in range(0, len(v), max(1, len(v) // 64)):
            want = (after[i] - before[i]) * (fps / 2.0)
            if (v[i] - want).GetLength() > 1e-3 * (1.0 + want.GetLength()):
                out.append(f"{where} @ {t}: velocity {tuple(v[i])} of point {i} is not the "
                           f"motion's {tuple(want)}")
                break
    return out


def check_curves(curves):
    """Failures of one BasisCurves prim over all its time codes: counts, widths and vertex
    primvars per point, finite points inside the extent."""
    out = []
    where = str(curves.GetPath())
    primvars = UsdGeom.PrimvarsAPI(curves).GetPrimvars()
    for t in time_codes(curves):
        tc = Usd.TimeCode(t) if not isinstance(t, Usd.TimeCode) else t
        at = f"{where} @ {'default' if tc.IsDefault() else t}"
        points = curves.GetPointsAttr().Get(tc) or []
        counts = curves.GetCurveVertexCountsAttr().Get(tc) or []
        if sum(counts) != len(points):
            out.append(f"{at}: sum(curveVertexCounts) = {sum(counts)} != {len(points)} points")
        if any(c < 2 for c in counts):
            out.append(f"{at}: a linear curve has fewer than 2 points")
        widths = curves.GetWidthsAttr().Get(tc)
        if widths is None or len(widths) != len(points):
            out.append(f"{at}: widths missing or not one per point")
        out += check_points(curves, primvars, tc, at, points)
    if curves.GetTypeAttr().Get() != UsdGeom.Tokens.linear:
        out.append(f"{where}: curves are not linear")
    return out


def validate(path):
    """Failures (strings) of one layer."""
    failures = []
    delegate = UsdUtils.CoalescingDiagnosticDelegate()
    try:
        stage = Usd.Stage.Open(str(path))
    except Exception as e:  # Tf.ErrorException on parse errors
        why = [d.commentary for d in delegate.TakeUncoalescedDiagnostics()] or [repr(e)]
        return [f"cannot open: {' | '.join(w.replace(chr(10), ' ') for w in why)}"]
    diagnostics = delegate.TakeUncoalescedDiagnostics()
    for d in diagnostics:
        failures.append(f"diagnostic while opening: {d.commentary}")
    get_errors = getattr(stage, "GetCompositionErrors", None)
    if get_errors is not None:
        failures += [f"composition error: {e}" for e in get_errors()]
    if not stage.GetDefaultPrim():
        failures.append("no defaultPrim")
    if UsdGeom.GetStageUpAxis(stage) != UsdGeom.Tokens.y:
        failures.append("upAxis is not Y")
    if stage.GetTimeCodesPerSecond() != stage.GetFramesPerSecond():
        failures.append("timeCodesPerSecond != framesPerSecond")
    failures += [f"compliance: {e}" for e in compliance(path)]
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    if not meshes:
        failures.append("no Mesh prim")
    for mesh in meshes:
        failures += check_mesh(mesh)
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.BasisCurves):
            failures += check_curves(UsdGeom.BasisCurves(prim))
    return failures


def main():
    if len(sys.argv) != 2:
        print(__doc__.splitlines()[2])
        return 2
    files = sorted(p for p in pathlib.Path(sys.argv[1]).rglob("*")
                   if p.suffix in (".usda", ".usdc", ".usdz"))
    passed = failed = 0
    for path in files:
        failures = validate(path)
        if failures:
            failed += 1
            for f in failures:
                print(f"{path}: {f}")
        else:
            passed += 1
    if not files:
        print(f"no .usda/.usdc/.usdz file in {sys.argv[1]}")
    print(f"USD validation: {passed} passed, {failed} failed")
    return 1 if failed or not files else 0


if __name__ == "__main__":
    sys.exit(main())
