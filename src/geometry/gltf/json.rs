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
