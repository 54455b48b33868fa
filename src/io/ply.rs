//! A PLY reader (ASCII, binary little- and big-endian) for triangle meshes: vertex
//! positions, optional normals and polygon faces (fan-triangulated). Unknown
//! properties and elements are skipped, in binary too (their sizes are computed
//! from the header). Every error names the file and, for ASCII, the line.

use crate::error::{Error, Result};
use glam::Vec3;
use std::path::Path;

/// What a PLY file yields: positions, triangles (vertex indices) and optional normals.
pub(crate) struct PlyData {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Debug)]
enum Kind {
    Scalar(Ty),
    List(Ty, Ty),
}

#[derive(Debug)]
struct Prop {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// Where the interesting data sits in the vertex and face elements.
struct Layout {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
    face_list: usize,
}

/// Parses a whole (decompressed) PLY file.
pub(crate) fn parse(data: &[u8], path: &Path) -> Result<PlyData> {
    let err = |msg: String| Error::mesh(path, msg);
    let (elements, format, body, header_lines) = parse_header(data, path)?;
    let vi = elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| err("PLY header has no 'vertex' element".into()))?;
    let fi =
        elements.iter().position(|e| e.name == "face").ok_or_else(|| err("PLY header has no 'face' element".into()))?;
    let find =
        |e: &Element, name: &str| e.props.iter().position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)));
    let ve = &elements[vi];
    let mut xyz = [0; 3];
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        xyz[k] = find(ve, name).ok_or_else(|| err(format!("PLY 'vertex' element has no scalar property '{name}'")))?;
    }
    let normal = match (find(ve, "nx"), find(ve, "ny"), find(ve, "nz")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    // Texture coordinates under the names PLY writers use (Blender and MeshLab:
    // `s t`; others `u v`, `texture_u texture_v`, `texture_s texture_t`).
    let uv = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"], ["texture_s", "texture_t"]]
        .iter()
        .find_map(|[a, b]| Some([find(ve, a)?, find(ve, b)?]));
    let fe = &elements[fi];
    let face_list = fe
        .props
        .iter()
        .position(|p| (p.name == "vertex_indices" || p.name == "vertex_index") && matches!(p.kind, Kind::List(..)))
        .ok_or_else(|| err("PLY 'face' element has no list property 'vertex_indices' or 'vertex_index'".into()))?;
    if let Kind::List(c, i) = fe.props[face_list].kind
        && (!c.is_int() || !i.is_int())
    {
        return Err(err("PLY face list must have integer count and index types".into()));
    }
    let layout = Layout { xyz, normal, uv, face_list };
    // The header can claim any count: reserve no more than the body can hold (every
    // element takes at least one byte), or a corrupt count aborts on allocation.
    let (nv, nf) = (ve.count.min(body.len()), fe.count.min(body.len()));
    let mut out = PlyData {
        positions: Vec::with_capacity(nv),
        triangles: Vec::with_capacity(nf * 2),
        normals: normal.map(|_| Vec::with_capacity(nv)),
        uvs: uv.map(|_| Vec::with_capacity(nv)),
    };
    match format {
        Format::Ascii => read_ascii(body, header_lines, &elements, vi, fi, &layout, &mut out, path)?,
        _ => read_binary(body, format, &elements, vi, fi, &layout, &mut out, path)?,
    }
    Ok(out)
}

type Header<'a> = (Vec<Element>, Format, &'a [u8], usize);

fn parse_header<'a>(data: &'a [u8], path: &Path) -> Result<Header<'a>> {
    let err = |line: usize, msg: String| Error::mesh(path, format!("line {line}: {msg}"));
    let mut pos = 0;
    let mut line_no = 0;
    let mut elements: Vec<Element> = Vec::new();
    let mut format = None;
    loop {
        line_no += 1;
        let Some(len) = data[pos..].iter().position(|&b| b == b'\n') else {
            return Err(err(line_no, "unexpected end of file in the PLY header (expected 'end_header')".into()));
        };
        let line = std::str::from_utf8(&data[pos..pos + len])
            .map_err(|_| err(line_no, "PLY header is not ASCII text".into()))?
            .trim();
        pos += len + 1;
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(err(1, format!("expected 'ply', found '{line}'")));
            }
            continue;
        }
        match words.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                format = Some(match words.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::LittleEndian,
                    Some("binary_big_endian") => Format::BigEndian,
                    other => return Err(err(line_no, format!("unknown PLY format {other:?}"))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count), 3) = (words.get(1), words.get(2), words.len()) else {
                    return Err(err(line_no, "expected 'element <name> <count>'".into()));
                };
                let count = count.parse().map_err(|_| err(line_no, format!("bad element count '{count}'")))?;
                elements.push(Element { name: name.to_string(), count, props: Vec::new() });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(err(line_no, "'property' before any 'element'".into()));
                };
                let ty = |s: &str| Ty::parse(s).ok_or_else(|| err(line_no, format!("unknown PLY type '{s}'")));
                let prop = match words.as_slice() {
                    ["property", "list", c, i, name] => {
                        Prop { name: name.to_string(), kind: Kind::List(ty(c)?, ty(i)?) }
                    }
                    ["property", t, name] => Prop { name: name.to_string(), kind: Kind::Scalar(ty(t)?) },
                    _ => {
                        return Err(err(
                            line_no,
                            "expected 'property <type> <name>' or 'property list <count type> <type> <name>'".into(),
                        ));
                    }
                };
                el.props.push(prop);
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(err(line_no, format!("unknown PLY header keyword '{other}'")));
            }
        }
    }
    let format = format.ok_or_else(|| err(line_no, "PLY header has no 'format' line".into()))?;
    Ok((elements, format, &data[pos..], line_no))
}

#[allow(clippy::too_many_arguments)]
fn read_ascii(
    body: &[u8],
    header_lines: usize,
    elements: &[Element],
    vi: usize,
    fi: usize,
    layout: &Layout,
    out: &mut PlyData,
    path: &Path,
) -> Result<()> {
    let text = std::str::from_utf8(body).map_err(|_| Error::mesh(path, "PLY body is not text (format says ascii)"))?;
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + header_lines + 1, l));
    let mut last_line = header_lines;
    let mut vals: Vec<f64> = Vec::new();
    let mut poly: Vec<i64> = Vec::new();
    for (ei, el) in elements.iter().enumerate() {
        for instance in 0..el.count {
            // Next non-blank line.
            let (ln, line) = loop {
                match lines.next() {
                    Some((ln, l)) if l.trim().is_empty() => last_line = ln,
                    Some(x) => break x,
                    None => {
                        return Err(Error::mesh(
                            path,
                            format!(
                                "line {}: unexpected end of file: expected {} '{}' lines, found {instance}",
                                last_line + 1,
                                el.count,
                                el.name
                            ),
                        ));
                    }
                }
            };
            last_line = ln;
            let err = |msg: String| Error::mesh(path, format!("line {ln}: {msg}"));
            let mut tok = line.split_ascii_whitespace();
            let mut next_num = |what: &dyn Fn() -> String| -> Result<f64> {
                let s = tok
                    .next()
                    .ok_or_else(|| err(format!("expected {} of element '{}', found end of line", what(), el.name)))?;
                s.parse::<f64>().map_err(|_| err(format!("expected a number for {}, found '{s}'", what())))
            };
            vals.clear();
            poly.clear();
            for (pi, p) in el.props.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(_) => vals.push(next_num(&|| format!("property '{}'", p.name))?),
                    Kind::List(..) => {
                        let n = next_num(&|| format!("the count of list '{}'", p.name))?;
                        if !(n >= 0.0 && n.fract() == 0.0) {
                            return Err(err(format!("bad list count {n} for '{}'", p.name)));
                        }
                        let n = n as usize;
                        for k in 0..n {
                            let v = next_num(&|| format!("vertex index {} of {n} in list '{}'", k + 1, p.name))?;
                            if ei == fi && pi == layout.face_list {
                                if v.fract() != 0.0 {
                                    return Err(err(format!("vertex index {v} is not an integer")));
                                }
                                poly.push(v as i64);
                            }
                        }
                        vals.push(0.0);
                    }
                }
            }
            if tok.next().is_some() {
                return Err(err(format!(
                    "more values than the {} properties of element '{}'",
                    el.props.len(),
                    el.name
                )));
            }
            if ei == vi {
                push_vertex(out, layout, |k| vals[k]);
            } else if ei == fi {
                push_polygon(out, &poly, elements[vi].count, err)?;
            }
        }
    }
    Ok(())
}

fn push_vertex(out: &mut PlyData, layout: &Layout, val: impl Fn(usize) -> f64) {
    let [x, y, z] = layout.xyz;
    out.positions.push(Vec3::new(val(x) as f32, val(y) as f32, val(z) as f32));
    if let (Some(ns), Some([a, b, c])) = (out.normals.as_mut(), layout.normal) {
        ns.push(Vec3::new(val(a) as f32, val(b) as f32, val(c) as f32));
    }
    if let (Some(uvs), Some([u, v])) = (out.uvs.as_mut(), layout.uv) {
        uvs.push([val(u) as f32, val(v) as f32]);
    }
}

/// Fan-triangulates one polygon after checking its indices.
fn push_polygon(out: &mut PlyData, poly: &[i64], n_vertices: usize, err: impl Fn(String) -> Error) -> Result<()> {
    if poly.len() < 3 {
        return Err(err(format!("expected at least 3 vertex indices, found {}", poly.len())));
    }
    for &i in poly {
        if i < 0 || i as usize >= n_vertices {
            return Err(err(format!("vertex index {i} out of range (the file has {n_vertices} vertices)")));
        }
    }
    for k in 1..poly.len() - 1 {
        out.triangles.push([poly[0] as u32, poly[k] as u32, poly[k + 1] as u32]);
    }
    Ok(())
}

/// A cursor over binary PLY data.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    big: bool,
}

impl Cursor<'_> {
    #[inline]
    fn read(&mut self, ty: Ty) -> Option<f64> {
        let n = ty.size();
        let b = self.data.get(self.pos..self.pos + n)?;
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        Some(match ty {
            Ty::I8 => a[0] as i8 as f64,
            Ty::U8 => a[0] as f64,
            Ty::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::F64 => f64::from_le_bytes(a),
        })
    }
}

#[allow(clippy::too_many_arguments)]
fn read_binary(
    body: &[u8],
    format: Format,
    elements: &[Element],
    vi: usize,
    fi: usize,
    layout: &Layout,
    out: &mut PlyData,
    path: &Path,
) -> Result<()> {
    let mut cur = Cursor { data: body, pos: 0, big: format == Format::BigEndian };
    let mut vals: Vec<f64> = Vec::new();
    let mut poly: Vec<i64> = Vec::new();
    for (ei, el) in elements.iter().enumerate() {
        for instance in 0..el.count {
            let err =
                |msg: String| Error::mesh(path, format!("element '{}' #{instance} (of {}): {msg}", el.name, el.count));
            let eof = || err("unexpected end of file (truncated?)".into());
            vals.clear();
            poly.clear();
            for (pi, p) in el.props.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(t) => vals.push(cur.read(t).ok_or_else(eof)?),
                    Kind::List(ct, it) => {
                        let n = cur.read(ct).ok_or_else(eof)?;
                        if n < 0.0 {
                            return Err(err(format!("negative list count {n}")));
                        }
                        let n = n as usize;
                        if ei == fi && pi == layout.face_list {
                            for _ in 0..n {
                                poly.push(cur.read(it).ok_or_else(eof)? as i64);
                            }
                        } else {
                            // Skip the items without decoding them.
                            let skip = n.checked_mul(it.size()).ok_or_else(eof)?;
                            if cur.pos + skip > body.len() {
                                return Err(eof());
                            }
                            cur.pos += skip;
                        }
                        vals.push(0.0);
                    }
                }
            }
            if ei == vi {
                push_vertex(out, layout, |k| vals[k]);
            } else if ei == fi {
                push_polygon(out, &poly, elements[vi].count, err)?;
            }
        }
    }
    Ok(())
}
