//! The `polydem contact` format: pairs of point clouds in, Minkowski contact features out, as JSON Lines.
//!
//! Input, one JSON object per line: `{"id": <any JSON>, "a": [[x,y,z], ...], "b": [[x,y,z], ...]}`, two
//! point clouds in world coordinates, each taken as its convex hull. Other fields are ignored (a checker may
//! keep its expected answers on the same line).
//!
//! Output, one line per non-blank input line, in input order:
//! `{"id", "status": "overlap"|"touching"|"separated", "depth", "distance", "normal", "point_a", "point_b",
//! "point", "solver"}` with the conventions of [`ContactGeometry`] (world frame, normal from a to b).
//! A line that cannot be answered (invalid UTF-8 or JSON, not an object, a missing or malformed field, fewer
//! than 4 points, a non-finite coordinate, a degenerate hull) yields `{"id", "line", "error"}` instead, where
//! `id` is present only when it could be read and `line` is the 1-based line number in the input; the other
//! lines are still answered. Lines that are empty or whitespace only are skipped and produce no output, but
//! still count for line numbers. A UTF-8 byte-order mark at the start of the input is skipped. The full
//! description is `docs/contact-jsonl.md`.
//!
//! Everything here is pure (reader in, writer out); the query itself is passed in.

use std::io::{BufRead, Write};

use serde::Serialize;
use serde_json::Value;

use crate::contact::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Pose, Real};
use crate::shape::{ConvexPolyhedron, ShapeError};

/// One parsed input line.
#[derive(Clone, Debug, PartialEq)]
pub struct PairInput {
    /// The line's `id`, any JSON value, echoed in the answer.
    pub id: Value,
    /// Vertices of shape A (world frame, m); the shape is their convex hull.
    pub a: Vec<Point>,
    /// Vertices of shape B (world frame, m); the shape is their convex hull.
    pub b: Vec<Point>,
}

/// Why one input line could not be answered.
#[derive(Debug, thiserror::Error)]
pub enum LineError {
    /// The line is not valid UTF-8.
    #[error("line is not valid UTF-8")]
    NotUtf8,
    /// The line is not valid JSON (the parser's message).
    #[error("invalid JSON: {0}")]
    Json(String),
    /// The JSON value is not an object.
    #[error("line is not a JSON object")]
    NotObject,
    /// A required field is absent.
    #[error("missing field `{0}`")]
    MissingField(&'static str),
    /// A point list is malformed.
    #[error("field `{field}`: {reason}")]
    BadPoints {
        /// The field.
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A point list does not make a convex polyhedron.
    #[error("shape `{field}`: {source}")]
    Shape {
        /// The field.
        field: &'static str,
        /// Why the shape could not be built.
        #[source]
        source: ShapeError,
    },
    /// The query produced a NaN or infinite value.
    #[error("the contact query returned a non-finite value")]
    NonFiniteResult,
}

/// The answer to one pair.
#[derive(Clone, Debug, Serialize)]
pub struct ContactRecord<'a> {
    /// The line's `id`.
    pub id: &'a Value,
    /// Overlap, touching or separated.
    pub status: ContactKind,
    /// Minkowski overlap δ_M (m); zero unless overlapping.
    pub depth: Real,
    /// Gap (m); zero unless separated.
    pub distance: Real,
    /// Unit normal n_M from A towards B (world frame).
    pub normal: [Real; 3],
    /// Contact point c1 on A (world frame, m).
    pub point_a: [Real; 3],
    /// Contact point c2 on B (world frame, m).
    pub point_b: [Real; 3],
    /// Midpoint c_M = (c1 + c2)/2 (world frame, m).
    pub point: [Real; 3],
    /// Which solver produced the answer.
    pub solver: SolverStatus,
}

/// The record written for a line that could not be answered.
#[derive(Clone, Debug, Serialize)]
pub struct ErrorRecord {
    /// The line's `id`, when it could be read.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub id: Option<Value>,
    /// Line number in the input (1-based).
    pub line: usize,
    /// What went wrong.
    pub error: String,
}

/// Counts of one run over a stream.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct StreamSummary {
    /// Lines answered with a contact record.
    pub answered: usize,
    /// Lines answered with an error record.
    pub errors: usize,
    /// Blank lines skipped.
    pub blank: usize,
}

/// Parses one (non-blank) line. On failure returns the id when it could be read, and the problem.
pub fn parse_pair(line: &str) -> Result<PairInput, (Option<Value>, LineError)> {
    let value: Value =
        serde_json::from_str(line).map_err(|e| (None, LineError::Json(e.to_string())))?;
    let Value::Object(mut object) = value else {
        return Err((None, LineError::NotObject));
    };
    let id = object
        .remove("id")
        .ok_or((None, LineError::MissingField("id")))?;
    let a = parse_points(object.get("a"), "a").map_err(|e| (Some(id.clone()), e))?;
    let b = parse_points(object.get("b"), "b").map_err(|e| (Some(id.clone()), e))?;
    Ok(PairInput { id, a, b })
}

fn parse_points(value: Option<&Value>, field: &'static str) -> Result<Vec<Point>, LineError> {
    let value = value.ok_or(LineError::MissingField(field))?;
    let Value::Array(items) = value else {
        return Err(LineError::BadPoints {
            field,
            reason: "expected an array of [x, y, z] points".to_string(),
        });
    };
    let mut points = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let coords = match item {
            Value::Array(c) if c.len() == 3 => c,
            _ => {
                return Err(LineError::BadPoints {
                    field,
                    reason: format!("point {i} is not an array of 3 numbers"),
                });
            }
        };
        let mut xyz = [0.0; 3];
        for (k, c) in coords.iter().enumerate() {
            xyz[k] = c.as_f64().ok_or_else(|| LineError::BadPoints {
                field,
                reason: format!("point {i} coordinate {k} is not a number"),
            })?;
        }
        points.push(Point::new(xyz[0], xyz[1], xyz[2]));
    }
    Ok(points)
}

/// Answers one parsed pair: builds both hulls and runs `query` on them at their world poses.
pub fn answer_pair<Q>(pair: &PairInput, query: &Q) -> Result<ContactGeometry, LineError>
where
    Q: Fn(&Pose, &ConvexPolyhedron, &Pose, &ConvexPolyhedron) -> ContactGeometry,
{
    let (a, pose_a) = ConvexPolyhedron::from_points(&pair.a)
        .map_err(|source| LineError::Shape { field: "a", source })?;
    let (b, pose_b) = ConvexPolyhedron::from_points(&pair.b)
        .map_err(|source| LineError::Shape { field: "b", source })?;
    let geometry = query(&pose_a, &a, &pose_b, &b);
    let finite = [geometry.depth, geometry.distance]
        .into_iter()
        .chain(geometry.normal.iter().copied())
        .chain(geometry.point_a.iter().copied())
        .chain(geometry.point_b.iter().copied())
        .chain(geometry.point.iter().copied())
        .all(Real::is_finite);
    if !finite {
        return Err(LineError::NonFiniteResult);
    }
    Ok(geometry)
}

/// The output line for input line `line_number` (1-based), or `None` for a blank line.
pub fn answer_line<Q>(line: &str, line_number: usize, query: &Q) -> Option<Result<String, String>>
where
    Q: Fn(&Pose, &ConvexPolyhedron, &Pose, &ConvexPolyhedron) -> ContactGeometry,
{
    if line.trim().is_empty() {
        return None;
    }
    let answer = parse_pair(line).and_then(|pair| match answer_pair(&pair, query) {
        Ok(geometry) => Ok(contact_json(&pair.id, &geometry)),
        Err(e) => Err((Some(pair.id), e)),
    });
    Some(answer.map_err(|(id, e)| error_json(id, line_number, &e)))
}

/// Serialises the answer to one pair.
pub fn contact_json(id: &Value, g: &ContactGeometry) -> String {
    let record = ContactRecord {
        id,
        status: g.kind,
        depth: g.depth,
        distance: g.distance,
        normal: g.normal.into(),
        point_a: g.point_a.coords.into(),
        point_b: g.point_b.coords.into(),
        point: g.point.coords.into(),
        solver: g.status,
    };
    serde_json::to_string(&record)
        .unwrap_or_else(|e| format!("{{\"error\":\"serialisation failed: {e}\"}}"))
}

/// Serialises the error record of one line.
pub fn error_json(id: Option<Value>, line: usize, error: &LineError) -> String {
    let record = ErrorRecord {
        id,
        line,
        error: error.to_string(),
    };
    serde_json::to_string(&record)
        .unwrap_or_else(|e| format!("{{\"line\":{line},\"error\":\"serialisation failed: {e}\"}}"))
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Answers every line of `input`, writing one output line per non-blank input line. Only I/O failures of
/// the reader or writer abort the run; every problem with a line's content becomes that line's error record.
pub fn answer_stream<R, W, Q>(
    mut input: R,
    mut output: W,
    query: &Q,
) -> std::io::Result<StreamSummary>
where
    R: BufRead,
    W: Write,
    Q: Fn(&Pose, &ConvexPolyhedron, &Pose, &ConvexPolyhedron) -> ContactGeometry,
{
    let mut summary = StreamSummary::default();
    let mut buffer = Vec::new();
    let mut line_number = 0;
    loop {
        buffer.clear();
        if input.read_until(b'\n', &mut buffer)? == 0 {
            break;
        }
        line_number += 1;
        // A byte-order mark some editors put at the start of a UTF-8 file is not part of the first line.
        let text = match buffer.strip_prefix(UTF8_BOM) {
            Some(rest) if line_number == 1 => rest,
            _ => &buffer[..],
        };
        let answer = match std::str::from_utf8(text) {
            Ok(line) => answer_line(line, line_number, query),
            Err(_) => Some(Err(error_json(None, line_number, &LineError::NotUtf8))),
        };
        match answer {
            None => summary.blank += 1,
            Some(Ok(record)) => {
                summary.answered += 1;
                writeln!(output, "{record}")?;
            }
            Some(Err(record)) => {
                summary.errors += 1;
                writeln!(output, "{record}")?;
            }
        }
    }
    output.flush()?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vector;

    /// A test double for the contact query: reports the two centroids as the contact points, so the tests
    /// can check which shapes and poses the format layer passed on.
    fn centroid_query(
        pos1: &Pose,
        _a: &ConvexPolyhedron,
        pos2: &Pose,
        _b: &ConvexPolyhedron,
    ) -> ContactGeometry {
        let c1 = Point::from(pos1.translation.vector);
        let c2 = Point::from(pos2.translation.vector);
        let d = c2 - c1;
        ContactGeometry::from_points(
            ContactKind::Separated,
            0.0,
            d.norm(),
            d.normalize(),
            c1,
            c2,
            SolverStatus::Exact,
        )
    }

    fn cube_json(centre: [Real; 3], half: Real) -> String {
        let mut corners = Vec::new();
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    corners.push(format!(
                        "[{},{},{}]",
                        centre[0] + sx * half,
                        centre[1] + sy * half,
                        centre[2] + sz * half
                    ));
                }
            }
        }
        format!("[{}]", corners.join(","))
    }

    #[test]
    fn parses_a_well_formed_line_and_ignores_extra_fields() {
        let line = format!(
            r#"{{"id": {{"case": 7}}, "a": {}, "b": {}, "expected_depth": 0.1}}"#,
            cube_json([0.0; 3], 1.0),
            cube_json([3.0, 0.0, 0.0], 1.0)
        );
        let pair = parse_pair(&line).unwrap();
        assert_eq!(pair.id, serde_json::json!({"case": 7}));
        assert_eq!((pair.a.len(), pair.b.len()), (8, 8));
        assert_eq!(pair.b[0], Point::new(2.0, -1.0, -1.0));
    }

    #[test]
    fn answers_with_the_hull_centroids_in_world_coordinates() {
        let line = format!(
            r#"{{"id": "p1", "a": {}, "b": {}}}"#,
            cube_json([0.0; 3], 1.0),
            cube_json([3.0, 1.0, 0.0], 0.5)
        );
        let out = answer_line(&line, 1, &centroid_query).unwrap().unwrap();
        let v: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["id"], "p1");
        assert_eq!(v["status"], "separated");
        assert_eq!(v["solver"], "exact");
        let point_b: Vec<Real> = v["point_b"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let err = (Vector::from_column_slice(&point_b) - Vector::new(3.0, 1.0, 0.0)).norm();
        assert!(
            err < 1e-14,
            "centroid of b {point_b:?}, expected [3, 1, 0], error {err:e}"
        );
        for key in ["depth", "distance", "normal", "point_a", "point"] {
            assert!(v.get(key).is_some(), "output lacks `{key}`: {out}");
        }
    }

    #[test]
    fn malformed_lines_give_error_records_with_line_and_id() {
        let cube = cube_json([0.0; 3], 1.0);
        let cases: Vec<(String, Option<Value>, &str)> = vec![
            ("{not json".to_string(), None, "invalid JSON"),
            ("[1, 2, 3]".to_string(), None, "not a JSON object"),
            (
                format!(r#"{{"a": {cube}, "b": {cube}}}"#),
                None,
                "missing field `id`",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}}}"#),
                Some(serde_json::json!(5)),
                "missing field `b`",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}, "b": [[0,0,0],[1,0,0],[0,1,0]]}}"#),
                Some(serde_json::json!(5)),
                "too few points",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}, "b": [[0,0,0],[1,0,0],[0,1,0],[1,1,0]]}}"#),
                Some(serde_json::json!(5)),
                "coplanar",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}, "b": [[0,0],[1,0,0],[0,1,0],[1,1,1]]}}"#),
                Some(serde_json::json!(5)),
                "point 0 is not an array of 3 numbers",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}, "b": [[0,0,"x"],[1,0,0],[0,1,0],[1,1,1]]}}"#),
                Some(serde_json::json!(5)),
                "coordinate 2 is not a number",
            ),
            (
                format!(r#"{{"id": 5, "a": {cube}, "b": [[0,0,1e999],[1,0,0],[0,1,0],[1,1,1]]}}"#),
                None,
                "invalid JSON",
            ),
            (
                format!(r#"{{"id": null, "a": {{}}, "b": {cube}}}"#),
                Some(Value::Null),
                "field `a`",
            ),
        ];
        for (line, id, expected) in cases {
            let out = answer_line(&line, 42, &centroid_query)
                .unwrap()
                .unwrap_err();
            let v: Value = serde_json::from_str(&out).unwrap();
            assert_eq!(v["line"], 42, "line number in {out}");
            assert!(
                v["error"].as_str().unwrap().contains(expected),
                "input {line}: error {out} should mention `{expected}`"
            );
            assert_eq!(v.get("id").cloned(), id, "id of error record {out}");
        }
    }

    #[test]
    fn stream_skips_blank_lines_and_keeps_order_and_line_numbers() {
        let good = |id: u32| {
            format!(
                r#"{{"id": {id}, "a": {}, "b": {}}}"#,
                cube_json([0.0; 3], 1.0),
                cube_json([5.0, 0.0, 0.0], 1.0)
            )
        };
        let input = format!("{}\n\n   \n{{oops\r\n{}\r\n{}", good(1), good(2), good(3));
        let mut output = Vec::new();
        let summary = answer_stream(input.as_bytes(), &mut output, &centroid_query).unwrap();
        assert_eq!(
            summary,
            StreamSummary {
                answered: 3,
                errors: 1,
                blank: 2
            }
        );
        let lines: Vec<Value> = String::from_utf8(output)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0]["id"], 1);
        assert_eq!(lines[1]["line"], 4);
        assert_eq!(lines[2]["id"], 2);
        assert_eq!(lines[3]["id"], 3);
    }

    #[test]
    fn invalid_utf8_is_an_error_record() {
        let mut input = b"\xff\xfe not utf8\n".to_vec();
        input.extend_from_slice(b"\n");
        let mut output = Vec::new();
        let summary = answer_stream(&input[..], &mut output, &centroid_query).unwrap();
        assert_eq!(
            summary,
            StreamSummary {
                answered: 0,
                errors: 1,
                blank: 1
            }
        );
        let v: Value =
            serde_json::from_slice(output.split(|&c| c == b'\n').next().unwrap()).unwrap();
        assert_eq!(v["line"], 1);
        assert!(v["error"].as_str().unwrap().contains("UTF-8"));
    }

    #[test]
    fn non_finite_query_results_become_error_records() {
        let nan_query = |p1: &Pose, a: &ConvexPolyhedron, p2: &Pose, b: &ConvexPolyhedron| {
            let mut g = centroid_query(p1, a, p2, b);
            g.depth = Real::NAN;
            g
        };
        let line = format!(
            r#"{{"id": "n", "a": {}, "b": {}}}"#,
            cube_json([0.0; 3], 1.0),
            cube_json([3.0, 0.0, 0.0], 1.0)
        );
        let out = answer_line(&line, 3, &nan_query).unwrap().unwrap_err();
        assert!(out.contains("non-finite"), "{out}");
        assert!(out.contains(r#""id":"n""#), "{out}");
    }
}
