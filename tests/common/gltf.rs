//! Writes small glTF 2.0 assets for the tests: JSON built with serde_json, binary data in
//! one buffer, written as a `.glb`, a `.gltf` with a base64 data URI, or a `.gltf` beside a
//! `.bin` file. Nothing here validates: the hostile-input tests write broken files with it.

use serde_json::{json, Value};

/// An asset being built: its JSON and the bytes of its one buffer.
pub struct GltfBuilder {
    pub json: Value,
    pub bin: Vec<u8>,
}

/// Standard base64 with padding (RFC 4648 §4).
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(A[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

impl Default for GltfBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl GltfBuilder {
    /// An empty glTF 2.0 asset.
    pub fn new() -> Self {
        Self {
            json: json!({"asset": {"version": "2.0"}}),
            bin: Vec::new(),
        }
    }

    /// Appends `value` to the top-level array `key`; returns its index.
    pub fn push(&mut self, key: &str, value: Value) -> usize {
        let root = self.json.as_object_mut().unwrap();
        let array = root.entry(key).or_insert_with(|| json!([]));
        let array = array.as_array_mut().unwrap();
        array.push(value);
        array.len() - 1
    }

    /// A buffer view of `bytes` (4-byte aligned in the buffer).
    pub fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(s) = stride {
            view["byteStride"] = json!(s);
        }
        self.push("bufferViews", view)
    }

    /// A FLOAT accessor of `ty` (`"VEC3"`, ...) over `values`, in a view of its own.
    pub fn floats(&mut self, values: &[f32], ty: &str, components: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        let count = values.len() / components;
        let mut accessor =
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": ty});
        if ty == "VEC3" && count > 0 {
            // POSITION accessors carry their bounds (glTF requires min and max).
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for p in values.chunks_exact(3) {
                for c in 0..3 {
                    min[c] = min[c].min(p[c]);
                    max[c] = max[c].max(p[c]);
                }
            }
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.push("accessors", accessor)
    }

    /// An UNSIGNED_INT index accessor.
    pub fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        self.push(
            "accessors",
            json!({"bufferView": view, "componentType": 5125, "count": indices.len(),
                   "type": "SCALAR"}),
        )
    }

    /// A triangle-list primitive of `mesh` (positions, normals, UVs when it has them,
    /// indices), drawn with material `material`.
    pub fn primitive(&mut self, mesh: &lucent::scene::Mesh, material: Option<usize>) -> Value {
        let p: Vec<f32> = mesh.positions.iter().flat_map(|v| v.to_array()).collect();
        let n: Vec<f32> = mesh.normals.iter().flat_map(|v| v.to_array()).collect();
        let position = self.floats(&p, "VEC3", 3);
        let normal = self.floats(&n, "VEC3", 3);
        let indices = self.indices(&mesh.indices);
        let mut primitive = json!({
            "attributes": {"POSITION": position, "NORMAL": normal},
            "indices": indices,
        });
        if !mesh.uvs.is_empty() {
            let t: Vec<f32> = mesh.uvs.iter().flat_map(|v| v.to_array()).collect();
            primitive["attributes"]["TEXCOORD_0"] = json!(self.floats(&t, "VEC2", 2));
        }
        if !mesh.tangents.is_empty() {
            let t: Vec<f32> = mesh.tangents.iter().flat_map(|v| v.to_array()).collect();
            primitive["attributes"]["TANGENT"] = json!(self.floats(&t, "VEC4", 4));
        }
        if let Some(m) = material {
            primitive["material"] = json!(m);
        }
        primitive
    }

    /// A mesh of `primitives` and a node drawing it, listed in scene 0; returns the node.
    pub fn mesh_node(&mut self, primitives: Vec<Value>, node: Value) -> usize {
        let mesh = self.push("meshes", json!({"primitives": primitives}));
        let mut node = node;
        node["mesh"] = json!(mesh);
        let n = self.push("nodes", node);
        self.add_root(n);
        n
    }

    /// Lists node `n` in scene 0 (made when missing).
    pub fn add_root(&mut self, n: usize) {
        if self.json.get("scenes").is_none() {
            self.push("scenes", json!({"nodes": []}));
            self.json["scene"] = json!(0);
        }
        self.json["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(n));
    }

    /// The JSON with its buffer described by `uri` (`None`: a GLB's BIN chunk).
    fn json_with_buffer(&self, uri: Option<String>) -> Value {
        let mut json = self.json.clone();
        if !self.bin.is_empty() && json.get("buffers").is_none() {
            let mut buffer = json!({"byteLength": self.bin.len()});
            if let Some(uri) = uri {
                buffer["uri"] = json!(uri);
            }
            json["buffers"] = json!([buffer]);
        }
        json
    }

    /// The asset as a `.gltf` with its buffer as a base64 data URI.
    pub fn gltf(&self) -> String {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        self.json_with_buffer(Some(uri)).to_string()
    }

    /// The asset as a `.gltf` naming `bin_name` for its buffer (write `self.bin` there).
    pub fn gltf_external(&self, bin_name: &str) -> String {
        self.json_with_buffer(Some(bin_name.to_string()))
            .to_string()
    }

    /// The asset as a `.glb`: header, JSON chunk, BIN chunk.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = self.json_with_buffer(None).to_string().into_bytes();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }
}

/// One triangle (positions only, +Z facing) as a glTF with it drawn by one node.
pub fn triangle() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3", 3);
    let i = b.indices(&[0, 1, 2]);
    b.mesh_node(
        vec![json!({"attributes": {"POSITION": p}, "indices": i})],
        json!({}),
    );
    b
}
