//! [`Bounded`]: a list of at most `N` items held inline (no heap), for the
//! results of the analyses that generated code calls per pose (the wrench
//! analysis and the stiffness: their limbs, rows and springs), whose sizes
//! the mechanism bounds.

use std::fmt;
use std::ops::{Deref, DerefMut};

/// At most `N` items, inline: a slice of the first `len` of an array.
/// It reads as a slice (`len`, indexing, `iter`).
#[derive(Clone, Copy)]
pub struct Bounded<T: Copy + Default, const N: usize> {
    items: [T; N],
    len: usize,
}

/// A [`Bounded`] was asked to hold more than its capacity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Full {
    /// Its capacity.
    pub capacity: usize,
}

impl<T: Copy + Default, const N: usize> Bounded<T, N> {
    /// No item.
    pub fn new() -> Self {
        Bounded {
            items: [T::default(); N],
            len: 0,
        }
    }

    /// The capacity `N`.
    pub const CAPACITY: usize = N;

    /// Appends `x`, or says the list is full.
    pub fn push(&mut self, x: T) -> Result<(), Full> {
        let slot = self.items.get_mut(self.len).ok_or(Full { capacity: N })?;
        *slot = x;
        self.len += 1;
        Ok(())
    }

    /// The items of `xs`, or that they are more than `N`.
    pub fn from_slice(xs: &[T]) -> Result<Self, Full> {
        let mut out = Self::new();
        for &x in xs {
            out.push(x)?;
        }
        Ok(out)
    }
}

impl<T: Copy + Default, const N: usize> Default for Bounded<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

/// From an array of at most `N` items (checked when compiled).
impl<T: Copy + Default, const N: usize, const K: usize> From<[T; K]> for Bounded<T, N> {
    fn from(xs: [T; K]) -> Self {
        const { assert!(K <= N, "more items than a Bounded holds") };
        let mut items = [T::default(); N];
        items[..K].copy_from_slice(&xs);
        Bounded { items, len: K }
    }
}

impl<T: Copy + Default, const N: usize> Deref for Bounded<T, N> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.items[..self.len]
    }
}

impl<T: Copy + Default, const N: usize> DerefMut for Bounded<T, N> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.items[..self.len]
    }
}

impl<'a, T: Copy + Default, const N: usize> IntoIterator for &'a Bounded<T, N> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<T: Copy + Default + fmt::Debug, const N: usize> fmt::Debug for Bounded<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<T: Copy + Default + PartialEq, const N: usize> PartialEq for Bounded<T, N> {
    fn eq(&self, other: &Self) -> bool {
        self[..] == other[..]
    }
}

impl<T: Copy + Default + PartialEq, const N: usize> PartialEq<Vec<T>> for Bounded<T, N> {
    fn eq(&self, other: &Vec<T>) -> bool {
        self[..] == other[..]
    }
}

impl<T: Copy + Default + PartialEq, const N: usize> PartialEq<[T]> for Bounded<T, N> {
    fn eq(&self, other: &[T]) -> bool {
        self[..] == *other
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_up_to_its_capacity() {
        let mut b: Bounded<usize, 2> = Bounded::new();
        assert!(b.is_empty());
        assert_eq!(b.push(4), Ok(()));
        assert_eq!(b.push(5), Ok(()));
        assert_eq!(b.push(6), Err(Full { capacity: 2 }));
        assert_eq!(b, vec![4, 5]);
        assert_eq!(Bounded::<usize, 3>::from([7, 8]), vec![7, 8]);
        assert_eq!(Bounded::<usize, 1>::from_slice(&[1, 2]), Err(Full { capacity: 1 }));
        assert_eq!(format!("{b:?}"), "[4, 5]");
    }
}
