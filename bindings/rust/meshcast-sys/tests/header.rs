//! The hand-written declarations of src/lib.rs against the header they
//! declare (include/meshcast/meshcast_c.h, read here as text): every
//! function with the same parameter and return types, every struct with the
//! same fields in the same order, every constant with the same value, and
//! the records' sizes as docs/c-api.md states them. A function, field or
//! constant added to one and not the other fails it.
use std::collections::BTreeMap;
use std::mem::size_of;

fn header() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../include/meshcast/meshcast_c.h");
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {}", path, e))
}

fn rust_source() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/lib.rs");
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {}", path, e))
}

/// The header without comments, its lines joined.
fn c_code() -> String {
    let text = header();
    let mut out = String::new();
    let mut rest = text.as_str();
    while let Some(start) = rest.find("/*") {
        out.push_str(&rest[..start]);
        let end = rest[start..].find("*/").expect("an unclosed comment") + start + 2;
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

fn squash(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A C type ("const meshcast_ray*", "uint32_t", "char**") as Rust spells it.
fn rust_type(c: &str) -> String {
    let c = squash(&c.replace('*', " * "));
    let mut tokens: Vec<&str> = c.split(' ').collect();
    let is_const = tokens.first() == Some(&"const");
    if is_const {
        tokens.remove(0);
    }
    let pointers = tokens.iter().filter(|t| **t == "*").count();
    let base = match tokens[0] {
        "char" => "c_char",
        "void" => "c_void",
        "uint32_t" => "u32",
        "uint64_t" => "u64",
        "float" => "f32",
        "double" => "f64",
        other => other,
    };
    if pointers == 0 {
        return base.to_string();
    }
    let mut out = "*mut ".repeat(pointers - 1);
    out.push_str(if is_const { "*const " } else { "*mut " });
    out.push_str(base);
    out
}

/// A C parameter ("const meshcast_ray* rays") as (name, Rust type).
fn c_parameter(p: &str) -> (String, String) {
    let p = squash(&p.replace('*', "* "));
    let split = p.rfind(' ').expect("a parameter without a name");
    (p[split + 1..].to_string(), rust_type(&p[..split]))
}

/// The header's functions: name -> (parameter types, return type).
fn c_functions() -> BTreeMap<String, (Vec<String>, String)> {
    let code = c_code();
    let mut out = BTreeMap::new();
    for declaration in code.split("MESHCAST_C_API ").skip(1) {
        let declaration = match declaration.find(';') {
            Some(end) => &declaration[..end],
            None => continue,
        };
        let open = match declaration.find('(') {
            Some(open) => open,
            None => continue, // the macro's own definition
        };
        let head = squash(&declaration[..open].replace('*', "* "));
        let split = head.rfind(' ').unwrap();
        let (returns, name) = (head[..split].to_string(), head[split + 1..].to_string());
        let inside = &declaration[open + 1..declaration.rfind(')').unwrap()];
        let parameters = if squash(inside) == "void" {
            vec![]
        } else {
            inside.split(',').map(|p| c_parameter(p).1).collect()
        };
        let returns = if returns == "void" { String::new() } else { rust_type(&returns) };
        out.insert(name, (parameters, returns));
    }
    out
}

/// src/lib.rs's extern functions: name -> (parameter types, return type).
fn rust_functions() -> BTreeMap<String, (Vec<String>, String)> {
    let source = rust_source();
    let block = &source[source.find("extern \"C\" {").expect("no extern block")..];
    let mut out = BTreeMap::new();
    for declaration in block.split("pub fn ").skip(1) {
        let declaration = &declaration[..declaration.find(';').unwrap()];
        let open = declaration.find('(').unwrap();
        let close = declaration.rfind(')').unwrap();
        let name = declaration[..open].trim().to_string();
        let parameters = declaration[open + 1..close]
            .split(',')
            .filter(|p| !p.trim().is_empty())
            .map(|p| squash(&p[p.find(':').unwrap() + 1..]))
            .collect();
        let returns = declaration[close + 1..].trim().trim_start_matches("->").trim().to_string();
        out.insert(name, (parameters, returns));
    }
    out
}

#[test]
fn every_function_matches_the_header() {
    let (c, rust) = (c_functions(), rust_functions());
    assert!(c.len() >= 40, "only {} functions read from the header", c.len());
    for (name, declared) in &c {
        match rust.get(name) {
            None => panic!("{} is in the header, not in src/lib.rs", name),
            Some(mine) => assert_eq!(mine, declared, "{}: src/lib.rs against the header", name),
        }
    }
    for name in rust.keys() {
        assert!(c.contains_key(name), "{} is in src/lib.rs, not in the header", name);
    }
}

/// The header's structs with fields: name -> [(field, Rust type)].
fn c_structs() -> BTreeMap<String, Vec<(String, String)>> {
    let code = c_code();
    let mut out = BTreeMap::new();
    for part in code.split("typedef struct ").skip(1) {
        let open = match part.find('{') {
            Some(open) if part[..open].find(';').is_none() => open,
            _ => continue, // an opaque handle
        };
        let name = part[..open].trim().to_string();
        let body = &part[open + 1..part.find('}').unwrap()];
        let mut fields = Vec::new();
        for line in body.split(';').map(squash).filter(|l| !l.is_empty()) {
            // "float u, v" declares two; "float org[3]" an array.
            let first = line.find(',').map(|c| line[..c].to_string()).unwrap_or_else(|| line.clone());
            let spaced = squash(&first.replace('*', "* "));
            let split = spaced.rfind(' ').unwrap();
            let base = rust_type(&spaced[..split]);
            let names = std::iter::once(spaced[split + 1..].to_string())
                .chain(line.split(',').skip(1).map(|n| n.trim().to_string()));
            for n in names {
                match n.find('[') {
                    Some(b) => fields.push((n[..b].to_string(), format!("[{}; {}]", base, &n[b + 1..n.len() - 1]))),
                    None => fields.push((n, base.clone())),
                }
            }
        }
        out.insert(name, fields);
    }
    out
}

/// src/lib.rs's structs with public fields.
fn rust_structs() -> BTreeMap<String, Vec<(String, String)>> {
    let source = rust_source();
    let mut out = BTreeMap::new();
    for part in source.split("pub struct ").skip(1) {
        let open = part.find('{').unwrap();
        let name = part[..open].trim().to_string();
        let body = &part[open + 1..part.find('}').unwrap()];
        let fields: Vec<(String, String)> = body
            .split(",\n")
            .map(squash)
            .filter(|f| f.starts_with("pub "))
            .map(|f| {
                let f = f.trim_end_matches(',');
                let colon = f.find(':').unwrap();
                (f[4..colon].trim().to_string(), squash(&f[colon + 1..]))
            })
            .collect();
        if !fields.is_empty() {
            out.insert(name, fields);
        }
    }
    out
}

#[test]
fn every_struct_matches_the_header() {
    let (c, rust) = (c_structs(), rust_structs());
    assert!(c.len() >= 15, "only {} structs read from the header", c.len());
    assert_eq!(c.keys().collect::<Vec<_>>(), rust.keys().collect::<Vec<_>>(), "the structs with fields");
    for (name, fields) in &c {
        assert_eq!(&rust[name], fields, "{}'s fields: src/lib.rs against the header", name);
    }
}

/// The header's integer constants (#defines and the status values).
fn c_constants() -> BTreeMap<String, u64> {
    let mut out = BTreeMap::new();
    let number = |text: &str| -> Option<u64> {
        let t = text.trim().trim_end_matches(|c| c == 'u' || c == 'U' || c == ',');
        if let Some(hex) = t.strip_prefix("0x") {
            u64::from_str_radix(hex, 16).ok()
        } else {
            t.parse().ok()
        }
    };
    for line in c_code().lines().map(str::trim) {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.len() == 3 && words[0] == "#define" {
            if let Some(v) = number(words[2]) {
                out.insert(words[1].to_string(), v);
            }
        } else if words.len() == 3 && words[0].starts_with("MESHCAST_") && words[1] == "=" {
            out.insert(words[0].to_string(), number(words[2]).unwrap());
        }
    }
    out
}

#[test]
fn every_constant_matches_the_header() {
    use meshcast_sys::*;
    let c = c_constants();
    let rust: BTreeMap<&str, u64> = [
        ("MESHCAST_C_API_VERSION_MAJOR", MESHCAST_C_API_VERSION_MAJOR as u64),
        ("MESHCAST_C_API_VERSION_MINOR", MESHCAST_C_API_VERSION_MINOR as u64),
        ("MESHCAST_OK", MESHCAST_OK as u64),
        ("MESHCAST_ERROR_INPUT", MESHCAST_ERROR_INPUT as u64),
        ("MESHCAST_ERROR_USAGE", MESHCAST_ERROR_USAGE as u64),
        ("MESHCAST_ERROR_OUTPUT", MESHCAST_ERROR_OUTPUT as u64),
        ("MESHCAST_ERROR_GPU", MESHCAST_ERROR_GPU as u64),
        ("MESHCAST_ERROR_OUT_OF_MEMORY", MESHCAST_ERROR_OUT_OF_MEMORY as u64),
        ("MESHCAST_ERROR_INTERNAL", MESHCAST_ERROR_INTERNAL as u64),
        ("MESHCAST_NO_HIT", MESHCAST_NO_HIT as u64),
        ("MESHCAST_LOAD_MAP", MESHCAST_LOAD_MAP as u64),
        ("MESHCAST_MEMORY_COPY", MESHCAST_MEMORY_COPY as u64),
        ("MESHCAST_MEMORY_BORROW", MESHCAST_MEMORY_BORROW as u64),
        ("MESHCAST_CLOSEST", MESHCAST_CLOSEST as u64),
        ("MESHCAST_ANY", MESHCAST_ANY as u64),
        ("MESHCAST_CULL_NONE", MESHCAST_CULL_NONE as u64),
        ("MESHCAST_CULL_BACK", MESHCAST_CULL_BACK as u64),
        ("MESHCAST_CULL_FRONT", MESHCAST_CULL_FRONT as u64),
        ("MESHCAST_HIT_UV", MESHCAST_HIT_UV as u64),
        ("MESHCAST_HIT_POINT", MESHCAST_HIT_POINT as u64),
        ("MESHCAST_BACKEND_CPU", MESHCAST_BACKEND_CPU as u64),
        ("MESHCAST_BACKEND_VULKAN", MESHCAST_BACKEND_VULKAN as u64),
        ("MESHCAST_BACKEND_AUTOMATIC", MESHCAST_BACKEND_AUTOMATIC as u64),
    ]
    .into_iter()
    .collect();
    for (name, value) in &c {
        assert_eq!(rust.get(name.as_str()), Some(value), "{}: src/lib.rs against the header", name);
    }
    assert_eq!(c.len(), rust.len(), "constants in src/lib.rs the header lacks");
    assert_eq!(MESHCAST_C_API_VERSION, (MESHCAST_C_API_VERSION_MAJOR << 16) | MESHCAST_C_API_VERSION_MINOR);
}

#[test]
fn the_records_have_their_stated_sizes() {
    use meshcast_sys::*;
    assert_eq!(size_of::<meshcast_ray>(), 32);
    assert_eq!(size_of::<meshcast_hit>(), 28);
    assert_eq!(size_of::<meshcast_ray_d>(), 48);
    assert_eq!(size_of::<meshcast_scene_hit>(), 20);
    assert_eq!(size_of::<meshcast_closest_point>(), 28);
    assert_eq!(size_of::<meshcast_scene_closest_point>(), 48);
}

#[test]
fn the_library_is_the_headers_version() {
    let version = unsafe { meshcast_sys::meshcast_api_version() };
    assert_eq!(version >> 16, meshcast_sys::MESHCAST_C_API_VERSION_MAJOR);
    assert!(version >= meshcast_sys::MESHCAST_C_API_VERSION);
}
