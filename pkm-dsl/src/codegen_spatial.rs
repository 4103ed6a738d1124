//! Generated spatial solvers: the plan's steps as constants, each executed
//! by the runtime's `spatial::execute` (the kernel the interpreter runs), on
//! joint geometry written out as expressions in the parameters.

use crate::geometry::{JointPlace, Vec3};
use crate::model::JointKind;
use crate::report::Analysis;
use pkm_runtime::plan::PointRef;
use pkm_runtime::spatial::{Anchor, Constraint, Direction, Hop, Plan, Step};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

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
    let m = quote! { ::pkm::runtime::model::Place };
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

fn point_ref(p: PointRef) -> TokenStream {
    match p {
        PointRef::Joint(j) => quote! { ::pkm::runtime::plan::PointRef::Joint(#j) },
        PointRef::Named(n) => quote! { ::pkm::runtime::plan::PointRef::Named(#n) },
    }
}

fn hops(h: &[Hop]) -> TokenStream {
    let items = h.iter().map(|Hop { joint, forward }| {
        quote! { ::pkm::runtime::spatial::Hop { joint: #joint, forward: #forward } }
    });
    quote! { ::std::borrow::Cow::Borrowed(&[#(#items),*]) }
}

fn anchor(a: &Anchor) -> TokenStream {
    let (link, h, p) = (a.link, hops(&a.hops), point_ref(a.point));
    quote! { ::pkm::runtime::spatial::Anchor { link: #link, hops: #h, point: #p } }
}

fn direction(d: &Direction) -> TokenStream {
    let (link, h, joint) = (d.link, hops(&d.hops), d.joint);
    quote! { ::pkm::runtime::spatial::Direction { link: #link, hops: #h, joint: #joint } }
}

fn option<T: quote::ToTokens>(o: Option<T>) -> TokenStream {
    match o {
        Some(v) => quote! { ::core::option::Option::Some(#v) },
        None => quote! { ::core::option::Option::None },
    }
}

/// A step as a constant expression.
fn step(s: &Step) -> TokenStream {
    let sp = quote! { ::pkm::runtime::spatial };
    match s {
        Step::Place {
            link,
            point,
            input,
            about,
        } => {
            let (p, about) = (
                point_ref(*point),
                option(about.map(|a| {
                    let [x, y, z] = a;
                    quote! { [#x, #y, #z] }
                })),
            );
            quote! { #sp::Step::Place { link: #link, point: #p, input: #input, about: #about } }
        }
        Step::Transfer { joint, from, to, input } => {
            quote! { #sp::Step::Transfer { joint: #joint, from: #from, to: #to, input: #input } }
        }
        Step::Aim {
            joint,
            from,
            to,
            point,
            target,
        } => {
            let (p, t) = (point_ref(*point), anchor(target));
            quote! { #sp::Step::Aim { joint: #joint, from: #from, to: #to, point: #p, target: #t } }
        }
        Step::Locus {
            joint,
            from,
            to,
            point,
            constraint,
            branch,
        } => {
            let p = point_ref(*point);
            let c = match constraint {
                Constraint::Sphere { centre, pa } => {
                    let c = anchor(centre);
                    quote! { #sp::Constraint::Sphere { centre: #c, pa: #pa } }
                }
                Constraint::Plane { normal, anchor: a } => {
                    let (n, a) = (direction(normal), anchor(a));
                    quote! { #sp::Constraint::Plane { normal: #n, anchor: #a } }
                }
                Constraint::Cylinder { hops: h, joint, link } => {
                    let h = hops(h);
                    quote! { #sp::Constraint::Cylinder { hops: #h, joint: #joint, link: #link } }
                }
                Constraint::Slider { hops: h, joint, link } => {
                    let h = hops(h);
                    quote! { #sp::Constraint::Slider { hops: #h, joint: #joint, link: #link } }
                }
            };
            let b = option(*branch);
            quote! { #sp::Step::Locus { joint: #joint, from: #from, to: #to, point: #p, constraint: #c, branch: #b } }
        }
        Step::Align {
            joint,
            from,
            to,
            group,
            target,
        } => {
            let (g, t) = (direction(group), direction(target));
            quote! { #sp::Step::Align { joint: #joint, from: #from, to: #to, group: #g, target: #t } }
        }
        Step::PaPlane {
            joint,
            from,
            to,
            pa,
            target,
        } => {
            let t = anchor(target);
            quote! { #sp::Step::PaPlane { joint: #joint, from: #from, to: #to, pa: #pa, target: #t } }
        }
    }
}

/// The body of a spatial solver, the expression of its solution, its number
/// of ± choices and its input joints.
pub fn body(a: &Analysis, plan: &Plan, sol_ty: &proc_macro2::Ident) -> (TokenStream, TokenStream, usize, Vec<usize>) {
    let m = &a.mechanism;
    let sp = quote! { ::pkm::runtime::spatial };
    let joints = m.joints.iter().enumerate().map(|(j, joint)| {
        let kind = match joint.kind {
            JointKind::P => quote! { P },
            JointKind::Pa => quote! { Pa },
            JointKind::S => quote! { S },
            _ => quote! { R },
        };
        let [u, v] = joint.links;
        let (p0, p1) = (place(a.place(j, u)), place(a.place(j, v)));
        quote! {
            #sp::Joint3::new(::pkm::runtime::model::JointType::#kind, [#u, #v], [#p0, #p1])
        }
    });
    let named: Vec<TokenStream> = a.geometry.points.iter().map(|p| xyz(&p.at)).collect();
    let n_named = named.len();
    let n_links = m.links.len();
    let mut steps = Vec::new();
    for (k, s) in plan.steps.iter().enumerate() {
        let c = format_ident!("STEP_{}", k);
        let s = step(s);
        steps.push(quote! {
            const #c: #sp::Step = #s;
            #sp::execute(#k, &#c, &joints, &named, &mut poses, q, &signs, |j| {
                ::std::borrow::Cow::Borrowed(Self::JOINTS[j])
            })?;
        });
    }
    let body = quote! {
        let joints = [#(#joints),*];
        let named: [[f64; 3]; #n_named] = [#(#named),*];
        let mut poses = [#sp::Pose3::identity(); #n_links];
        #(#steps)*
    };
    let mut points = Vec::new();
    for j in 0..m.joints.len() {
        let l = a.point_link(j);
        let at = xyz(a.place(j, l).at());
        points.push(quote! { #sp::at(&poses[#l], #at) });
    }
    for (k, np) in a.geometry.points.iter().enumerate() {
        let l = np.link;
        points.push(quote! { #sp::at(&poses[#l], named[#k]) });
    }
    let (lets, outputs) = crate::codegen_fk::outputs(a, |link, at, about| {
        let local = match at {
            PointRef::Joint(j) => xyz(a.place(j, link).at()),
            PointRef::Named(n) => quote! { named[#n] },
        };
        let at = quote! { #sp::at(&poses[#link], #local) };
        match about {
            crate::codegen_fk::Angle::About(k) => {
                let k = xyz(k);
                quote! {{ let [x, y, z] = #at; [x, y, z, #sp::angle_about(&poses[#link], #k)] }}
            }
            _ => at,
        }
    });
    let result = quote! {{
        let values = #sp::values(&joints, &poses);
        #lets
        #sol_ty { q: values, points: [#(#points),*], outputs: [#(#outputs),*] }
    }};
    (body, result, plan.branches, plan.inputs.clone())
}
