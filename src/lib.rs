//! # pkm
//!
//! A compiler for the topology and kinematics of parallel mechanisms, by the
//! POC method (position and orientation characteristics; Yang Tingli, Shen
//! Huiping). A mechanism is declared in a small language; at compile time
//! [`mechanism!`] parses it, computes its topology (POC sets, full-cycle
//! DOF, loop equations ξ_L, SOC constraint degrees Δ, sub-kinematic chains,
//! coupling degree κ, motion decoupling) and emits a type that carries it.
//!
//! ```
//! pkm::mechanism!(pub FourBar, "
//!     mechanism four_bar {
//!         capabilities fk, ik;
//!         planar;
//!         base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
//!     }
//! ");
//!
//! assert_eq!(FourBar::DOF, 1);
//! assert_eq!(FourBar::XI, &[3]);
//! assert_eq!(FourBar::DELTA, &[0]);
//! assert_eq!(FourBar::KAPPA, 0);
//! assert_eq!(FourBar::REPORT.skc_count(), 1);
//! ```
//!
//! A description can also live in a `.pkm` file, read relative to the
//! crate's `Cargo.toml` (edits rebuild):
//!
//! ```
//! pkm::mechanism!(pub MechanismA, file = "examples/mechanisms/seed000_a.pkm");
//!
//! assert_eq!(MechanismA::PLATFORM_POC, Some("[t²(∥◇xoz); r¹(∥R6)]"));
//! assert_eq!((MechanismA::DOF, MechanismA::XI, MechanismA::DELTA), (3, &[3, 5][..], &[0, 0][..]));
//! ```
//!
//! With `capabilities ik, stiffness;`, `units` and a `limbs` block, the
//! type gives the platform's static stiffness at a pose on one branch: the
//! limbs' actuation and constraint wrenches (`J`), `K = Jᵀ K_p J` and the
//! deflection under a wrench, about the point the outputs place (N and
//! the file's length unit; docs/stiffness.md):
//!
//! ```
//! pkm::mechanism!(pub Rps, file = "examples/mechanisms/rps_3.pkm");
//!
//! let params = RpsParams::default();
//! let home = [75.0, 0.0, 0.0]; // Z_A (mm), α, β (rad)
//! // The assembly with the shortest legs (P1, P2, P3 are joints 1, 4, 7).
//! let legs = |q: &[f64; 9]| q[1].abs() + q[4].abs() + q[7].abs();
//! let branch = Rps::ik(&params, &home)
//!     .into_iter()
//!     .filter_map(|b| b.result.ok().map(|s| (legs(&s.q), b.signs)))
//!     .min_by(|a, b| a.0.total_cmp(&b.0))
//!     .unwrap();
//! let k = Rps::stiffness(&params, &home, branch.1).unwrap();
//! assert_eq!(k.jacobian().shape(), (6, 6)); // 3 actuation, 3 constraint forces
//! let deflection = k.deflection(&[10.0, -15.0, 20.0, -2.0e4, 1.0e4, 1.5e4]).unwrap();
//! assert!(deflection.iter().all(|d| d.abs() < 1e-3)); // mm and rad
//! let [kx, ky, kz, ..] = k.directional().unwrap(); // N/mm
//! assert!(kz > kx && kz > ky); // seed 004: Z is the stiffest direction
//! ```
//!
//! ## The language
//!
//! ```text
//! mechanism NAME {
//!     title "…";                         // optional
//!     capabilities fk, ik;               // what to generate (analysis is always done)
//!     planar;                            // rotations about z, slides in xoy
//!
//!     branch I {                         // a limb from the base to the platform
//!         base P1* ⊥ R11 [c1] ∥ R12 [c2] ∥ R13 ⊥ P2* base;   // a chain; `*` = actuated
//!         c2 R3 ⊥ R4 platform;           // `[c2]` named the link between R12 and R13
//!     }
//!     R3 ≡ R12;                          // coaxial (a compound hinge)
//!     x ∥ P1 ∥ P2;                       // relations, also across branches; x, y, z = frame
//!     Pa ⊥ ◇xoz;                         // planes: a frame plane or ◇(A,B), the plane of two axes
//!     point o on R4;                     // the platform's base point
//!
//!     link 1 "AB, crank", 2 "BCD";       // planar linkages as links and joints
//!     joint A = R(base, 1)*;
//!     joint G = R(7, 4, 5);              // compound hinge: 3 links, 2 joints
//!     platform = 7;                      // when the platform is not named `platform`
//! }
//! ```
//!
//! Joint types are the prefix of a chain joint's name: `R`, `P`, `H`, `C`,
//! `U`, `S` and `Pa` (parallelogram: one translational DOF, its internal
//! loop not counted). Every symbol has an ASCII spelling: `||` for `∥`,
//! `_|_` for `⊥`, `==` for `≡`, `<>` for `◇`.
//!
//! Requesting `fk` for a design whose coupling degree κ is not zero is a
//! compile error that names the SKC, its Δ values and the virtual variables
//! its forward solution would need; with only `ik` it compiles.
#![deny(missing_docs)]

/// The compiler as a library (parser, topology analysis, code generation),
/// with the feature `compiler`; the macro needs none of it at run time.
#[cfg(feature = "compiler")]
pub use pkm_dsl as dsl;
pub use pkm_macros::mechanism;
/// The runtime: shared types that generated code uses.
pub use pkm_runtime as runtime;
