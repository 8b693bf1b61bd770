//! Reading glTF's JSON: arrays, indices and numbers, each checked where it is read so that an error names the
//! property, and integers accepted however the JSON writes them (`24` or `24.0`: JSON has one number type, and the
//! glTF Validator accepts integral floats where an integer is required).

use serde_json::Value;

/// The largest integer a JSON number holds exactly as an f64 (2^53).
const MAX_EXACT: f64 = 9_007_199_254_740_992.0;

/// `json[key]` as a slice (empty when absent or not an array).
pub fn array<'v>(json: &'v Value, key: &str) -> &'v [Value] {
    json.get(key)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

/// A non-negative integer, written as an integer or as an integral float (`3.0`); None for anything else.
pub fn uint(v: &Value) -> Option<u64> {
    match v {
        Value::Number(n) => n.as_u64().or_else(|| {
            n.as_f64()
                .filter(|f| f.fract() == 0.0 && (0.0..=MAX_EXACT).contains(f))
                .map(|f| f as u64)
        }),
        _ => None,
    }
}

/// An optional non-negative integer property: None when absent (or null), an error naming `what` when present
/// but not an integer.
pub fn opt_uint(v: &Value, what: impl FnOnce() -> String) -> Result<Option<u64>, String> {
    match v {
        Value::Null => Ok(None),
        _ => uint(v)
            .map(Some)
            .ok_or_else(|| format!("{} is {v}, not a non-negative integer", what())),
    }
}

/// A non-negative integer property that defaults to `default` when absent.
pub fn uint_or(v: &Value, default: u64, what: impl FnOnce() -> String) -> Result<u64, String> {
    Ok(opt_uint(v, what)?.unwrap_or(default))
}

/// An index below `len` (a required reference to another object of the document).
pub fn index(v: &Value, what: impl FnOnce() -> String, len: usize) -> Result<usize, String> {
    match uint(v) {
        Some(i) if (i as usize) < len && i <= usize::MAX as u64 => Ok(i as usize),
        _ => Err(format!("{} is {v}, not an index below {len}", what())),
    }
}

/// An optional index below `len`: None when absent.
pub fn opt_index(
    v: &Value,
    what: impl FnOnce() -> String,
    len: usize,
) -> Result<Option<usize>, String> {
    match v {
        Value::Null => Ok(None),
        _ => index(v, what, len).map(Some),
    }
}

/// An array of exactly `N` finite numbers, None when absent.
pub fn floats<const N: usize>(v: &Value, what: &str) -> Result<Option<[f32; N]>, String> {
    let Some(a) = v.as_array() else {
        return match v {
            Value::Null => Ok(None),
            _ => Err(format!("{what} is not an array")),
        };
    };
    if a.len() != N {
        return Err(format!("{what} has {} numbers, not {N}", a.len()));
    }
    let mut out = [0.0f32; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = finite(x).ok_or_else(|| format!("{what} holds {x}, not a finite number"))?;
    }
    Ok(Some(out))
}

/// An array of finite numbers of any length, None when absent.
pub fn float_list(v: &Value, what: &str) -> Result<Option<Vec<f32>>, String> {
    let Some(a) = v.as_array() else {
        return match v {
            Value::Null => Ok(None),
            _ => Err(format!("{what} is not an array")),
        };
    };
    a.iter()
        .map(|x| finite(x).ok_or_else(|| format!("{what} holds {x}, not a finite number")))
        .collect::<Result<Vec<f32>, String>>()
        .map(Some)
}

/// A number property that defaults to `default` when absent; an error naming `what` when it is not a finite
/// number.
pub fn number_or(v: &Value, default: f32, what: impl FnOnce() -> String) -> Result<f32, String> {
    match v {
        Value::Null => Ok(default),
        _ => finite(v).ok_or_else(|| format!("{} is {v}, not a finite number", what())),
    }
}

/// A finite number that is also finite as an f32.
fn finite(x: &Value) -> Option<f32> {
    x.as_f64().map(|x| x as f32).filter(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn integers_may_be_written_as_integral_floats() {
        assert_eq!(uint(&json!(24)), Some(24));
        assert_eq!(uint(&json!(24.0)), Some(24));
        assert_eq!(uint(&json!(0.0)), Some(0));
        assert_eq!(uint(&json!(24.5)), None);
        assert_eq!(uint(&json!(-1)), None);
        assert_eq!(uint(&json!(-1.0)), None);
        assert_eq!(uint(&json!(1e300)), None);
        assert_eq!(uint(&json!("24")), None);
        assert_eq!(index(&json!(2.0), || "x".into(), 3), Ok(2));
        let e = index(&json!(3.0), || "node 0's mesh".into(), 3).unwrap_err();
        assert!(
            e.contains("node 0's mesh is 3.0, not an index below 3"),
            "{e}"
        );
    }

    #[test]
    fn optional_integers_are_absent_or_integers() {
        assert_eq!(opt_uint(&Value::Null, || "s".into()), Ok(None));
        assert_eq!(opt_uint(&json!(12.0), || "s".into()), Ok(Some(12)));
        let e = opt_uint(&json!("12"), || "bufferView 0's byteStride".into()).unwrap_err();
        assert!(e.contains("byteStride is \"12\""), "{e}");
        assert_eq!(uint_or(&Value::Null, 4, || "m".into()), Ok(4));
    }

    #[test]
    fn float_arrays_have_their_length_and_finite_values() {
        assert_eq!(floats::<2>(&json!([1, 2.5]), "t"), Ok(Some([1.0, 2.5])));
        assert_eq!(floats::<2>(&Value::Null, "t"), Ok(None));
        assert!(floats::<2>(&json!([1]), "t").is_err());
        assert!(floats::<1>(&json!([1e300]), "t").is_err());
        assert_eq!(float_list(&json!([0.5, 1]), "w"), Ok(Some(vec![0.5, 1.0])));
        assert!(float_list(&json!({}), "w").is_err());
    }
}

/// The top-level collections of a glTF 2.0 document: arrays of objects where present.
const COLLECTIONS: [&str; 14] = [
    "accessors",
    "animations",
    "buffers",
    "bufferViews",
    "cameras",
    "images",
    "materials",
    "meshes",
    "nodes",
    "samplers",
    "scenes",
    "skins",
    "textures",
    "extensionsRequired",
];

/// The glTF 2.0 schema's shapes of what lodbench reads: each top-level collection an array (of objects, but for
/// `extensionsRequired`), each mesh's `primitives` an array of objects, each primitive's `attributes` an object,
/// each node's `children`, `matrix`, `translation`, `rotation`, `scale` and `weights` arrays. A part of the wrong
/// JSON type is named here, rather than read as if absent (which made a mesh whose `primitives` is an object look
/// like a mesh of points and lines).
pub fn check_shapes(json: &Value) -> Result<(), String> {
    let kind = |v: &Value| match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    };
    let wrong = |path: String, v: &Value, want: &str| {
        format!(
            "{path} is {}, not {want}: the file does not follow the glTF 2.0 schema (the Khronos glTF Validator \
             lists every such defect); export it again from its source, or fix that property",
            kind(v)
        )
    };
    let arrays_of_objects = |path: &str, v: &Value, objects: bool| -> Result<(), String> {
        let items = v
            .as_array()
            .ok_or_else(|| wrong(path.to_string(), v, "an array"))?;
        match items.iter().position(|i| objects && !i.is_object()) {
            Some(i) => Err(wrong(format!("{path}[{i}]"), &items[i], "an object")),
            None => Ok(()),
        }
    };
    for key in COLLECTIONS {
        if let Some(v) = json.get(key) {
            arrays_of_objects(key, v, key != "extensionsRequired")?;
        }
    }
    for (m, mesh) in array(json, "meshes").iter().enumerate() {
        match mesh.get("primitives") {
            Some(p) => arrays_of_objects(&format!("meshes[{m}].primitives"), p, true)?,
            None => {
                return Err(format!(
                    "meshes[{m}] has no primitives, which glTF 2.0 requires"
                ))
            }
        }
        for (p, prim) in array(mesh, "primitives").iter().enumerate() {
            match prim.get("attributes") {
                Some(a) if !a.is_object() => {
                    return Err(wrong(
                        format!("meshes[{m}].primitives[{p}].attributes"),
                        a,
                        "an object",
                    ))
                }
                _ => {}
            }
        }
    }
    for (n, node) in array(json, "nodes").iter().enumerate() {
        for key in [
            "children",
            "matrix",
            "translation",
            "rotation",
            "scale",
            "weights",
        ] {
            if let Some(v) = node.get(key).filter(|v| !v.is_array()) {
                return Err(wrong(format!("nodes[{n}].{key}"), v, "an array"));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod shape_tests {
    use super::check_shapes;
    use serde_json::json;

    fn doc(extra: serde_json::Value) -> serde_json::Value {
        let mut d = json!({"asset": {"version": "2.0"},
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "nodes": [{"mesh": 0, "translation": [0, 0, 0]}]});
        for (k, v) in extra.as_object().unwrap() {
            d[k] = v.clone();
        }
        d
    }

    #[test]
    fn a_well_formed_document_passes() {
        assert_eq!(check_shapes(&doc(json!({}))), Ok(()));
    }

    /// assimp's test/models/glTF2/wrongTypes/badArray.gltf: `primitives` an object holding one primitive.
    #[test]
    fn primitives_as_an_object_is_named() {
        let d =
            doc(json!({"meshes": [{"primitives": {"not an array": {"POSITION": 2}, "mode": 4}}]}));
        let e = check_shapes(&d).unwrap_err();
        assert!(
            e.starts_with("meshes[0].primitives is an object, not an array: the file does not follow the glTF 2.0"),
            "{e}"
        );
    }

    #[test]
    fn each_wrong_shape_is_named_by_its_path() {
        for (extra, path) in [
            (
                json!({"nodes": {"a": 1}}),
                "nodes is an object, not an array",
            ),
            (
                json!({"accessors": [3]}),
                "accessors[0] is a number, not an object",
            ),
            (
                json!({"meshes": [{"primitives": [{"attributes": [0]}]}]}),
                "meshes[0].primitives[0].attributes is an array, not an object",
            ),
            (
                json!({"meshes": [{"name": "m"}]}),
                "meshes[0] has no primitives",
            ),
            (
                json!({"nodes": [{"children": 1}]}),
                "nodes[0].children is a number, not an array",
            ),
            (
                json!({"extensionsRequired": "KHR_x"}),
                "extensionsRequired is a string, not an array",
            ),
        ] {
            let e = check_shapes(&doc(extra)).unwrap_err();
            assert!(e.starts_with(path), "{e}");
        }
    }
}
