//! glTF guards that run before the gltf crate parses a document: what its validation
//! assumes without checking (a bad index there would be a panic inside the crate).

/// Checks what gltf-json 1.4 validation assumes without checking: that every mesh
/// attribute refers to an existing accessor, and that every accessor has elements.
/// The error is the message; the reader wraps it as a malformed-glTF error.
pub(crate) fn precheck(root: &gltf_json::Root) -> Result<(), String> {
    use gltf_json::validation::Checked;
    for (k, a) in root.animations.iter().enumerate() {
        for c in &a.channels {
            if matches!(c.target.path, Checked::Invalid) {
                return Err(format!("animation {k} targets an unknown property"));
            }
            if c.target.node.value() >= root.nodes.len() || c.sampler.value() >= a.samplers.len() {
                return Err(format!("animation {k} refers to a missing node or sampler"));
            }
        }
        if a.samplers
            .iter()
            .any(|s| matches!(s.interpolation, Checked::Invalid))
        {
            return Err(format!("animation {k} has an unknown interpolation"));
        }
    }
    // A byte stride shorter than the element would make accessor reads overlap.
    for (k, a) in root.accessors.iter().enumerate() {
        // glTF 2.0 requires count ≥ 1; the gltf crate's reader computes `count - 1`.
        if a.count.0 == 0 {
            return Err(format!(
                "accessor {k} has count 0 (glTF requires at least one element): remove the accessor or re-export the file"
            ));
        }
        let (Checked::Valid(ty), Checked::Valid(ct)) = (&a.type_, &a.component_type) else {
            continue;
        };
        let stride = a
            .buffer_view
            .and_then(|v| root.buffer_views.get(v.value()))
            .and_then(|v| v.byte_stride);
        if let Some(st) = stride {
            if st.0 < ty.multiplicity() * ct.0.size() {
                return Err(format!(
                    "accessor {k}: byteStride {} is shorter than its elements",
                    st.0
                ));
            }
        }
    }
    let n = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        if mesh
            .primitives
            .iter()
            .any(|p| matches!(p.mode, Checked::Invalid))
        {
            return Err(format!("mesh {m} has an unknown primitive mode"));
        }
        for p in &mesh.primitives {
            let refs = p.attributes.values().chain(p.indices.iter());
            let targets = p.targets.iter().flatten().flat_map(|t| {
                t.positions
                    .iter()
                    .chain(t.normals.iter())
                    .chain(t.tangents.iter())
            });
            if let Some(bad_ref) = refs.chain(targets).find(|i| i.value() >= n) {
                return Err(format!(
                    "mesh {m} refers to accessor {} but there are {n}",
                    bad_ref.value()
                ));
            }
        }
    }
    Ok(())
}
