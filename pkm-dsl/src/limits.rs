//! Every size the compiler accepts, in one place. Each limit is far above any
//! real mechanism and is checked before the work it protects, so that no text
//! can crash the compiler, hang it or make it allocate without bound; going
//! past one is a [`Diagnostic`](crate::Diagnostic) that states the limit.

/// The longest mechanism text, in bytes (a real one is under 10 kB). The
/// parser's token list takes up to about 240 bytes per byte of text (a sum
/// `1+1+…`), so this also bounds its memory to about 60 MB.
pub const MAX_FILE_BYTES: usize = 1 << 18;

/// The deepest nesting of an expression: open parentheses plus pending `^`
/// exponents (`a^b^c` nests twice), counted together (a real one nests < 10).
/// The parser recurses once per level.
pub const MAX_NESTING: usize = 64;

/// The most operations (`+ − * / ^`, unary minus, function calls) in one
/// expression (a real one has < 30). Expressions are trees evaluated
/// recursively, so this also bounds that recursion.
pub const MAX_EXPR_OPERATIONS: usize = 512;

/// The most parameters in a mechanism (a real one has < 200).
pub const MAX_PARAMETERS: usize = 10_000;

/// The most placements (joints placed on links and named points) in a
/// `geometry` block (a real one has < 300). Checking them is quadratic.
pub const MAX_PLACEMENTS: usize = 4096;

/// The most joints, and the most links, of a mechanism (a real one has < 100
/// joints): joint sets are 64-bit masks in the topology analysis. This also
/// bounds the loops: v = m − n + 1 ≤ 63.
pub const MAX_JOINTS: usize = 64;

/// The most relations (`∥ ⊥ ≡` between two directions, written in chains and
/// relation statements) in a mechanism (a real one has < 200).
pub const MAX_RELATIONS: usize = 4096;

/// The most arithmetic the search for the ordered single open chains may
/// spend, in multiply-adds of its rank computations (about a second). The
/// search is exponential in the loops at worst; past this it stops and says so.
pub const MAX_ORDERING_WORK: u64 = 1_500_000_000;
