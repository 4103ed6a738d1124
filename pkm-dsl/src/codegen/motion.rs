//! Generated velocity capabilities (`jacobian`, `velocity`, `acceleration`):
//! the numeric model and the outputs written out as expressions in the
//! parameters, handed to the runtime's differentiated loop equations.

use crate::semantics::geometry::OutputKind;
use crate::semantics::geometry::{JointPlace, Vec3};
use crate::semantics::mechanism::Capability;
use crate::topology::analysis::Analysis;
use pkm_runtime::solution::PointRef;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

/// The items of the requested velocity capabilities; empty if none is asked for.
pub fn generate(a: &Analysis, ident: &proc_macro2::Ident) -> Result<TokenStream, crate::Diagnostics> {
    let m = &a.mechanism;
    // The forward solution by a virtual variable polishes on the model too.
    let wanted = [
        Capability::Jacobian,
        Capability::Velocity,
        Capability::Acceleration,
        Capability::FkNumeric,
    ];
    if !a.geometry.complete || !wanted.iter().any(|c| m.wants(*c)) {
        return Ok(TokenStream::new());
    }
    // The numeric model must exist (every joint type has one).
    crate::lowering::numeric::model(a, &std::collections::HashMap::new())?;
    let s = Signature::of(a, ident);
    let model = model_fns(a, &s);
    let jacobian = m.wants(Capability::Jacobian).then(|| jacobian_fn(&s));
    let velocity = m.wants(Capability::Velocity).then(|| velocity_fns(&s));
    let acceleration = m.wants(Capability::Acceleration).then(|| acceleration_fns(&s));
    Ok(quote! {
        #[automatically_derived]
        impl #ident {
            #model
            #jacobian
            #velocity
            #acceleration
        }
    })
}

/// The types and sizes the velocity functions are written with.
struct Signature {
    params_ty: proc_macro2::Ident,
    n_joints: usize,
    n_inputs: usize,
    n_outputs: usize,
    n_points: usize,
    dim: usize,
}

impl Signature {
    fn of(a: &Analysis, ident: &proc_macro2::Ident) -> Self {
        let m = &a.mechanism;
        Signature {
            params_ty: format_ident!("{}Params", ident),
            n_joints: m.joints.len(),
            n_inputs: m.joints.iter().filter(|j| j.actuated).count(),
            n_outputs: a.geometry.outputs.iter().map(|o| o.names.len()).sum(),
            n_points: m.joints.len() + a.geometry.points.len(),
            dim: if m.planar { 2 } else { 3 },
        }
    }

    /// A function of every point's motion (order `POINTS`) at `q`: the
    /// link poses there, `points` (the runtime's 3-D list, from `model`
    /// and `poses`) copied into the solution's point array.
    fn points_fn(&self, doc: &str, name: &TokenStream, arg: &TokenStream, points: &TokenStream) -> TokenStream {
        let Signature {
            params_ty,
            n_joints,
            n_points,
            dim,
            ..
        } = self;
        let rt = quote! { ::pkm::runtime::__private };
        quote! {
            #[doc = #doc]
            pub fn #name(
                params: &#params_ty,
                q: &[f64; #n_joints],
                #arg,
            ) -> ::core::result::Result<[[f64; #dim]; #n_points], #rt::velocity::VelocityError> {
                let model = Self::model(params);
                let poses = #rt::kinematics::link_poses(&model, q)?;
                let points = #points;
                let mut out = [[0.0; #dim]; #n_points];
                for (o, p) in out.iter_mut().zip(&points) {
                    o.copy_from_slice(&p[..#dim]);
                }
                ::core::result::Result::Ok(out)
            }
        }
    }
}

/// `model` (the numeric model at `params`) and `output_specs` (the
/// declared outputs in numbers), the velocity analysis's data.
fn model_fns(a: &Analysis, s: &Signature) -> TokenStream {
    let m = &a.mechanism;
    let rt = quote! { ::pkm::runtime::__private };
    let params_ty = &s.params_ty;
    let joints = m.joints.iter().enumerate().map(|(j, joint)| {
        let kind = joint_type(joint.kind);
        let [u, v] = joint.links;
        let (p0, p1) = (place(a.place(j, u)), place(a.place(j, v)));
        let (name, actuated) = (&joint.name, joint.actuated);
        quote! {
            #rt::model::Joint {
                name: ::std::string::String::from(#name),
                kind: #kind,
                links: [#u, #v],
                places: [#p0, #p1],
                actuated: #actuated,
            }
        }
    });
    let links = m.links.iter().map(|l| &l.name);
    let points = a.geometry.points.iter().map(|p| {
        let (name, link, at) = (&p.name, p.link, xyz(&p.at));
        quote! {
            #rt::model::NamedPoint { name: ::std::string::String::from(#name), link: #link, at: #at }
        }
    });
    let local = |point: PointRef, link: usize| match point {
        PointRef::Joint(j) => xyz(a.place(j, link).at()),
        PointRef::Named(n) => xyz(&a.geometry.points[n].at),
    };
    let outputs = a.geometry.outputs.iter().map(|o| match &o.kind {
        OutputKind::Pose { link, point, about } => {
            let at = local(*point, *link);
            let about = match about {
                Some(k) => {
                    let k = xyz(k);
                    quote! { ::core::option::Option::Some(#k) }
                }
                None if m.planar => quote! { ::core::option::Option::Some([0.0, 0.0, 1.0]) },
                None => quote! { ::core::option::Option::None },
            };
            quote! { #rt::newton::Output::Pose { link: #link, local: #at, about: #about } }
        }
        OutputKind::Point { link, point } => {
            let at = local(*point, *link);
            quote! { #rt::newton::Output::Point { link: #link, local: #at } }
        }
        OutputKind::Parts { link, point, parts } => {
            let at = local(*point, *link);
            let given = parts.0;
            quote! {
                #rt::newton::Output::Parts {
                    link: #link,
                    local: #at,
                    parts: #rt::steps::place::PoseParts([#(#given),*]),
                }
            }
        }
        OutputKind::Joint(j) => quote! { #rt::newton::Output::Joint(#j) },
    });
    let (name, planar) = (&m.name, m.planar);
    quote! {
        /// The numeric model at `params`, which the velocity analysis reads
        /// and the forward solution by a virtual variable polishes on.
        pub fn model(params: &#params_ty) -> #rt::model::Model {
            let _ = params;
            #rt::model::Model {
                name: ::std::string::String::from(#name),
                planar: #planar,
                links: ::std::vec::Vec::from([#(::std::string::String::from(#links)),*]),
                joints: ::std::vec::Vec::from([#(#joints),*]),
                points: ::std::vec::Vec::from([#(#points),*]),
            }
        }

        /// The declared outputs in numbers at `params`.
        pub fn output_specs(params: &#params_ty) -> ::std::vec::Vec<#rt::newton::Output> {
            let _ = params;
            ::std::vec::Vec::from([#(#outputs),*])
        }
    }
}

/// `jacobian`: the forward and inverse velocity maps at joint values.
fn jacobian_fn(s: &Signature) -> TokenStream {
    let Signature {
        params_ty, n_joints, ..
    } = s;
    let v = quote! { ::pkm::runtime::__private::velocity };
    quote! {
        /// The forward velocity map (outputs per input rate) and the
        /// inverse one (inputs per output rate) at the joint values `q`,
        /// and how far `q` is from an output and an input singularity.
        pub fn jacobian(params: &#params_ty, q: &[f64; #n_joints]) -> ::core::result::Result<#v::Jacobians, #v::VelocityError> {
            #v::jacobians(&Self::model(params), q, &Self::output_specs(params))
        }
    }
}

/// `velocity`, `output_rates` and `point_velocities`.
fn velocity_fns(s: &Signature) -> TokenStream {
    let Signature {
        params_ty,
        n_joints,
        n_inputs,
        n_outputs,
        ..
    } = s;
    let rt = quote! { ::pkm::runtime::__private };
    let v = quote! { #rt::velocity };
    let point_velocities = s.points_fn(
        " The velocity of every point (order `POINTS`) for velocities at `q`.",
        &quote! { point_velocities },
        &quote! { v: &#v::Velocities },
        &quote! { #v::point_velocities(&model, &poses, &v.twists) },
    );
    quote! {
        /// Every joint rate and link twist at the joint values `q` for the
        /// inputs' rates (their order is `INPUTS`'s).
        pub fn velocity(
            params: &#params_ty,
            q: &[f64; #n_joints],
            input_rates: &[f64; #n_inputs],
        ) -> ::core::result::Result<#v::Velocities, #v::VelocityError> {
            #v::velocities(&Self::model(params), q, input_rates)
        }

        /// The declared outputs' rates (order `OUTPUTS`) for velocities at `q`.
        pub fn output_rates(
            params: &#params_ty,
            q: &[f64; #n_joints],
            v: &#v::Velocities,
        ) -> ::core::result::Result<[f64; #n_outputs], #v::VelocityError> {
            let model = Self::model(params);
            let poses = #rt::kinematics::link_poses(&model, q)?;
            let rates = #v::output_rates(&model, &poses, &Self::output_specs(params), &v.rates, &v.twists);
            let mut out = [0.0; #n_outputs];
            out.copy_from_slice(&rates);
            ::core::result::Result::Ok(out)
        }

        #point_velocities
    }
}

/// `acceleration` and `point_accelerations`.
fn acceleration_fns(s: &Signature) -> TokenStream {
    let Signature {
        params_ty,
        n_joints,
        n_inputs,
        ..
    } = s;
    let v = quote! { ::pkm::runtime::__private::velocity };
    let point_accelerations = s.points_fn(
        " The acceleration of every point (order `POINTS`) for accelerations at `q`.",
        &quote! { point_accelerations },
        &quote! { a: &#v::Accelerations },
        &quote! { #v::point_accelerations(&model, &poses, a) },
    );
    quote! {
        /// Every joint's rate and second derivative and every link's twist
        /// and twist rate at `q` for the inputs' rates and second derivatives.
        pub fn acceleration(
            params: &#params_ty,
            q: &[f64; #n_joints],
            input_rates: &[f64; #n_inputs],
            input_accelerations: &[f64; #n_inputs],
        ) -> ::core::result::Result<#v::Accelerations, #v::VelocityError> {
            #v::accelerations(&Self::model(params), q, input_rates, input_accelerations)
        }

        #point_accelerations
    }
}

pub(crate) fn xyz(v: &Vec3) -> TokenStream {
    let params = quote! { params };
    let (x, y, z) = (
        v[0].to_tokens(&params),
        v[1].to_tokens(&params),
        v[2].to_tokens(&params),
    );
    quote! { [#x, #y, #z] }
}

pub(crate) fn place(p: &JointPlace) -> TokenStream {
    let m = quote! { ::pkm::runtime::__private::model::Place };
    match p {
        JointPlace::Point(at, Some(axis)) => {
            let (at, axis) = (xyz(at), xyz(axis));
            quote! { #m::Axis { at: #at, axis: #axis } }
        }
        JointPlace::Point(at, None) => {
            let at = xyz(at);
            quote! { #m::Point { at: #at } }
        }
        JointPlace::Line(at, along) => {
            let (at, along) = (xyz(at), xyz(along));
            quote! { #m::Line { through: #at, along: #along } }
        }
        JointPlace::Arm(at, axis, arm) => {
            let (at, axis, arm) = (xyz(at), xyz(axis), xyz(arm));
            quote! { #m::Arm { at: #at, axis: #axis, arm: #arm } }
        }
    }
}

/// The runtime's joint type of a joint kind, as tokens.
fn joint_type(kind: crate::semantics::mechanism::JointKind) -> TokenStream {
    let t = match crate::codegen::solver::joint_type(kind) {
        pkm_runtime::model::JointType::P => quote! { P },
        pkm_runtime::model::JointType::Pa => quote! { Pa },
        pkm_runtime::model::JointType::S => quote! { S },
        pkm_runtime::model::JointType::R => quote! { R },
    };
    quote! { ::pkm::runtime::__private::model::JointType::#t }
}
