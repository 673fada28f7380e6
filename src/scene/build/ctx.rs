//! The scene's text and path, and the checks every table shares: each turns a span into the
//! `FILE:LINE: FIELD: message` of a [`SceneError::Invalid`].

use std::ops::Range;
use std::path::Path;

use toml::Spanned;

use crate::law::LawError;
use crate::math::{Real, Vector};

use super::super::schema::Vec3;
use super::SceneError;

pub(super) struct Ctx<'a> {
    pub path: &'a Path,
    pub source: &'a str,
}

impl Ctx<'_> {
    pub fn line_column(&self, offset: usize) -> (usize, usize) {
        let before = &self.source[..offset.min(self.source.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        (line, column)
    }

    pub fn invalid(
        &self,
        span: Range<usize>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_owned(),
            line: self.line_column(span.start).0,
            field: field.into(),
            message: message.into(),
        }
    }

    pub fn positive(&self, v: &Spanned<f64>, field: &str) -> Result<Real, SceneError> {
        let x = *v.get_ref();
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(
                v.span(),
                field,
                format!("must be finite and positive, got {x}"),
            ))
        }
    }

    pub fn vector(&self, v: &Spanned<Vec3>, field: &str) -> Result<Vector, SceneError> {
        let a = v.get_ref();
        if a.iter().all(|x| x.is_finite()) {
            Ok(Vector::new(a[0], a[1], a[2]))
        } else {
            Err(self.invalid(v.span(), field, format!("must be finite, got {a:?}")))
        }
    }

    /// An optional vector, zero when absent.
    pub fn vector_or_zero(
        &self,
        v: &Option<Spanned<Vec3>>,
        field: &str,
    ) -> Result<Vector, SceneError> {
        Ok(v.as_ref()
            .map(|v| self.vector(v, field))
            .transpose()?
            .unwrap_or_else(Vector::zeros))
    }

    pub fn law(&self, span: Range<usize>, field: &str, e: LawError) -> SceneError {
        self.invalid(span, field, e.to_string())
    }
}
