//! `[[interaction]]`: the contact law of a pair of materials, one [`ContactModel`] per pair, from the law's
//! scene key (`"linear"`, `"power"`, `"hertz_mindlin"`) and its parameters.

use crate::law::hertz_mindlin::{material_hertz_mindlin, HertzMindlinOptions};
use crate::law::{ContactModel, DampingLaw, NormalLaw, SpringRotation, TangentialLaw};
use crate::math::Real;

use super::super::schema::{InteractionSection, SceneFile};
use super::materials::Materials;
use super::{Ctx, SceneError};

/// What every law of one `[[interaction]]` reads besides its own parameters.
struct Common<'a> {
    k: usize,
    it: &'a InteractionSection,
    ids: [u32; 2],
    /// Coulomb friction μ ≥ 0.
    friction: Real,
    limit_force: bool,
}

impl Common<'_> {
    fn field(&self, name: &str) -> String {
        format!("interaction[{}].{name}", self.k)
    }
}

/// Sets the law of every material pair an `[[interaction]]` names.
pub(super) fn read(
    ctx: &Ctx,
    file: &SceneFile,
    materials: &mut Materials,
) -> Result<(), SceneError> {
    for (k, it) in file.interactions.iter().enumerate() {
        let c = common(ctx, k, it, materials)?;
        let law = it.law.get_ref().as_str();
        let model = match law {
            "hertz_mindlin" => hertz_mindlin(ctx, file, materials, &c)?,
            "linear" | "power" => power_law(ctx, law, &c)?,
            other => {
                return Err(ctx.invalid(
                    it.law.span(),
                    c.field("law"),
                    format!(
                    "unknown law '{other}' (expected \"linear\", \"power\" or \"hertz_mindlin\")"
                ),
                ))
            }
        };
        let model = spring_rotation(ctx, &c, model)?;
        materials.table.set_model(c.ids[0], c.ids[1], model);
    }
    Ok(())
}

/// The pair (known materials without a law yet), the friction and the force limit.
fn common<'a>(
    ctx: &Ctx,
    k: usize,
    it: &'a InteractionSection,
    materials: &Materials,
) -> Result<Common<'a>, SceneError> {
    let f = |s: &str| format!("interaction[{k}].{s}");
    let [a, b] = it.materials.get_ref();
    let ids = [a, b].map(|n| materials.find(n.as_str()));
    let (Some(ia), Some(ib)) = (ids[0], ids[1]) else {
        let missing = if ids[0].is_none() { a } else { b };
        return Err(ctx.invalid(
            it.materials.span(),
            f("materials"),
            format!("unknown material '{missing}'"),
        ));
    };
    if materials.table.model(ia, ib).is_some() {
        return Err(ctx.invalid(
            it.materials.span(),
            f("materials"),
            format!("a law for ('{a}', '{b}') is already given"),
        ));
    }
    let mu = *it.friction.get_ref();
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(ctx.invalid(
            it.friction.span(),
            f("friction"),
            format!("must be finite and ≥ 0, got {mu}"),
        ));
    }
    Ok(Common {
        k,
        it,
        ids: [ia, ib],
        friction: mu,
        limit_force: it.limit_force.as_ref().is_some_and(|b| *b.get_ref()),
    })
}

/// `law = "hertz_mindlin"`: stiffnesses from the materials' E and ν, damping from the restitution.
fn hertz_mindlin(
    ctx: &Ctx,
    file: &SceneFile,
    materials: &Materials,
    c: &Common,
) -> Result<ContactModel, SceneError> {
    let it = c.it;
    let foreign = [
        (
            "normal_stiffness",
            it.normal_stiffness.as_ref().map(|v| v.span()),
        ),
        ("exponent", it.exponent.as_ref().map(|v| v.span())),
        (
            "tangential_stiffness",
            it.tangential_stiffness.as_ref().map(|v| v.span()),
        ),
        (
            "normal_damping",
            it.normal_damping.as_ref().map(|v| v.span()),
        ),
    ];
    for (field, span) in foreign {
        if let Some(span) = span {
            return Err(ctx.invalid(span, c.field(field), format!("the hertz_mindlin law takes no {field}: its stiffnesses follow from the materials' young_modulus and poisson_ratio and each contact's R*, its damping from the restitution")));
        }
    }
    let restitution = it.restitution.as_ref().ok_or_else(|| {
        ctx.invalid(
            it.law.span(),
            c.field("restitution"),
            "the hertz_mindlin law needs a restitution e (0 < e ≤ 1)",
        )
    })?;
    let k = c.k;
    let constants = |id: u32| {
        materials.elastic[id as usize].ok_or_else(|| {
            let m = &file.materials[id as usize];
            ctx.invalid(
                m.name.span(),
                format!("material[{id}].young_modulus"),
                format!("material '{}' needs young_modulus and poisson_ratio: interaction[{k}] uses the hertz_mindlin law", m.name.get_ref()),
            )
        })
    };
    let options = HertzMindlinOptions {
        tangential_damping: it.tangential_damping.as_ref().is_none_or(|b| *b.get_ref()),
        limit_force: c.limit_force,
    };
    material_hertz_mindlin(
        &constants(c.ids[0])?,
        &constants(c.ids[1])?,
        *restitution.get_ref(),
        c.friction,
        options,
    )
    .map_err(|e| ctx.law(restitution.span(), &c.field("restitution"), e))
}

/// `law = "linear"` or `"power"`: given stiffnesses, damping from a restitution or a dashpot.
fn power_law(ctx: &Ctx, law: &str, c: &Common) -> Result<ContactModel, SceneError> {
    if let Some(td) = &c.it.tangential_damping {
        return Err(ctx.invalid(
            td.span(),
            c.field("tangential_damping"),
            format!("the {law} law has no tangential dashpot (only hertz_mindlin)"),
        ));
    }
    let normal = normal_law(ctx, law, c)?;
    Ok(ContactModel {
        normal,
        damping: damping_law(ctx, law, c, normal.exponent)?,
        tangential: tangential_law(ctx, c)?,
    })
}

/// k_n and n of a linear or power law, with the force limit.
fn normal_law(ctx: &Ctx, law: &str, c: &Common) -> Result<NormalLaw, SceneError> {
    let it = c.it;
    let k_n_value = it.normal_stiffness.as_ref().ok_or_else(|| {
        ctx.invalid(
            it.law.span(),
            c.field("normal_stiffness"),
            format!("the {law} law needs normal_stiffness"),
        )
    })?;
    let k_n = ctx.positive(k_n_value, &c.field("normal_stiffness"))?;
    let exponent = match (law, &it.exponent) {
        ("linear", None) => 1.0,
        ("linear", Some(e)) => {
            return Err(ctx.invalid(
                e.span(),
                c.field("exponent"),
                "the linear law has no exponent (use law = \"power\")",
            ))
        }
        (_, Some(e)) => *e.get_ref(),
        (_, None) => {
            return Err(ctx.invalid(
                it.law.span(),
                c.field("exponent"),
                "the power law needs an exponent n (1 ≤ n ≤ 3)",
            ))
        }
    };
    let exponent_span = it.exponent.as_ref().map_or(it.law.span(), |e| e.span());
    let normal = NormalLaw::new(k_n, exponent)
        .map_err(|e| ctx.law(exponent_span, &c.field("exponent"), e))?;
    Ok(if c.limit_force {
        normal.with_force_limit()
    } else {
        normal
    })
}

/// The normal damping: a restitution, or (linear law only) a constant dashpot.
fn damping_law(ctx: &Ctx, law: &str, c: &Common, exponent: Real) -> Result<DampingLaw, SceneError> {
    let it = c.it;
    match (&it.restitution, &it.normal_damping) {
        (Some(e), None) => DampingLaw::from_restitution(exponent, *e.get_ref())
            .map_err(|err| ctx.law(e.span(), &c.field("restitution"), err)),
        (None, Some(d)) if law == "linear" => DampingLaw::dashpot(*d.get_ref())
            .map_err(|err| ctx.law(d.span(), &c.field("normal_damping"), err)),
        (None, Some(d)) => Err(ctx.invalid(
            d.span(),
            c.field("normal_damping"),
            "a constant dashpot is available for the linear law only; give a restitution",
        )),
        (Some(_), Some(d)) => Err(ctx.invalid(
            d.span(),
            c.field("normal_damping"),
            "give either restitution or normal_damping, not both",
        )),
        (None, None) => Err(ctx.invalid(
            it.law.span(),
            c.field("restitution"),
            "give a restitution e (0 < e ≤ 1) or, for the linear law, a normal_damping c_n (N s/m)",
        )),
    }
}

/// The tangential spring of a linear or power law. No tangential history at all when μ = 0: the spring
/// could carry no force.
fn tangential_law(ctx: &Ctx, c: &Common) -> Result<TangentialLaw, SceneError> {
    let mu = c.friction;
    match (&c.it.tangential_stiffness, mu > 0.0) {
        (None, false) => Ok(TangentialLaw::None),
        (Some(k_t), _) => {
            let k_t_value = ctx.positive(k_t, &c.field("tangential_stiffness"))?;
            if mu > 0.0 {
                TangentialLaw::spring(k_t_value, mu)
                    .map_err(|e| ctx.law(k_t.span(), &c.field("tangential_stiffness"), e))
            } else {
                Ok(TangentialLaw::None)
            }
        }
        (None, true) => Err(ctx.invalid(
            c.it.friction.span(),
            c.field("tangential_stiffness"),
            "friction > 0 needs a tangential_stiffness",
        )),
    }
}

/// `spring_rotation`: how the tangential spring follows the turning normal; absent = the law's own.
fn spring_rotation(ctx: &Ctx, c: &Common, model: ContactModel) -> Result<ContactModel, SceneError> {
    let Some(r) = &c.it.spring_rotation else {
        return Ok(model);
    };
    let rotation = match r.get_ref().as_str() {
        "exact" => SpringRotation::Exact,
        "projection" => SpringRotation::Projection,
        other => {
            return Err(ctx.invalid(
                r.span(),
                c.field("spring_rotation"),
                format!("unknown spring_rotation '{other}' (expected \"exact\" or \"projection\")"),
            ))
        }
    };
    Ok(ContactModel {
        tangential: model.tangential.with_rotation(rotation),
        ..model
    })
}
