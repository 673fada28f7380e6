//! `[[material]]`: names, densities and the elastic constants the `hertz_mindlin` law needs; the
//! [`MaterialTable`] the interactions then fill with laws.

use toml::Spanned;

use crate::fixed_hash::FixedHashMap;
use crate::law::hertz_mindlin::ElasticMaterial;
use crate::math::Real;
use crate::world::MaterialTable;

use super::super::schema::MaterialSection;
use super::{Ctx, SceneError};

/// The materials of a scene, by id (their order in the file).
pub(super) struct Materials<'a> {
    /// The world's table: names, and the laws of the pairs ([`super::interactions`]).
    pub table: MaterialTable,
    ids: FixedHashMap<&'a str, u32>,
    /// Density (kg/m³) by id.
    pub densities: Vec<Real>,
    /// E and ν by id, when given.
    pub elastic: Vec<Option<ElasticMaterial>>,
}

impl<'a> Materials<'a> {
    pub fn read(ctx: &Ctx, sections: &'a [MaterialSection]) -> Result<Self, SceneError> {
        let mut materials = Materials {
            table: MaterialTable::default(),
            ids: FixedHashMap::default(),
            densities: Vec::new(),
            elastic: Vec::new(),
        };
        for (k, m) in sections.iter().enumerate() {
            let name = m.name.get_ref().as_str();
            if materials.ids.contains_key(name) {
                return Err(ctx.invalid(
                    m.name.span(),
                    format!("material[{k}].name"),
                    format!("duplicate material '{name}'"),
                ));
            }
            let density = ctx.positive(&m.density, &format!("material[{k}].density"))?;
            materials.densities.push(density);
            materials.elastic.push(elastic_constants(ctx, k, m)?);
            materials
                .ids
                .insert(name, materials.table.add_material(name));
        }
        Ok(materials)
    }

    /// The id of a material name, if declared.
    pub fn find(&self, name: &str) -> Option<u32> {
        self.ids.get(name).copied()
    }

    /// The id of the material a table names in `field`; an unknown name is an error on its line.
    pub fn id(&self, ctx: &Ctx, name: &Spanned<String>, field: String) -> Result<u32, SceneError> {
        self.find(name.get_ref().as_str()).ok_or_else(|| {
            ctx.invalid(
                name.span(),
                field,
                format!("unknown material '{}'", name.get_ref()),
            )
        })
    }
}

/// `young_modulus` and `poisson_ratio`: both or neither.
fn elastic_constants(
    ctx: &Ctx,
    k: usize,
    m: &MaterialSection,
) -> Result<Option<ElasticMaterial>, SceneError> {
    match (&m.young_modulus, &m.poisson_ratio) {
        (None, None) => Ok(None),
        (Some(young), Some(poisson)) => {
            let e = ctx.positive(young, &format!("material[{k}].young_modulus"))?;
            Ok(Some(ElasticMaterial::new(e, *poisson.get_ref()).map_err(
                |err| ctx.law(poisson.span(), &format!("material[{k}].poisson_ratio"), err),
            )?))
        }
        (Some(young), None) => Err(ctx.invalid(
            young.span(),
            format!("material[{k}].poisson_ratio"),
            "young_modulus needs poisson_ratio as well",
        )),
        (None, Some(poisson)) => Err(ctx.invalid(
            poisson.span(),
            format!("material[{k}].young_modulus"),
            "poisson_ratio needs young_modulus as well",
        )),
    }
}
