//! A lane that counts its arithmetic: the kernel's floating-point operations per body, counted
//! by running the same lane-generic code on it rather than by hand (a count by hand goes stale
//! with the first change to the kernel).

use std::cell::Cell;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Lane, Portable};
use crate::math::{Narrow, Real, Widen};

/// Floating-point operations of one body's step through a kernel, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpCounts {
    /// Additions and subtractions.
    pub add: u64,
    /// Multiplications.
    pub mul: u64,
    /// Divisions.
    pub div: u64,
    /// Square roots.
    pub sqrt: u64,
}

impl OpCounts {
    /// All of them: the kernel's flops.
    pub fn total(&self) -> u64 {
        self.add + self.mul + self.div + self.sqrt
    }
}

thread_local! {
    static COUNTS: Cell<OpCounts> = const {
        Cell::new(OpCounts { add: 0, mul: 0, div: 0, sqrt: 0 })
    };
}

/// Adds one operation to this thread's counts.
fn count(kind: fn(&mut OpCounts) -> &mut u64) {
    COUNTS.with(|c| {
        let mut counts = c.get();
        *kind(&mut counts) += 1;
        c.set(counts);
    });
}

/// Runs `f` and returns what it counted on this thread.
pub(crate) fn counted<R>(f: impl FnOnce() -> R) -> (R, OpCounts) {
    let before = COUNTS.with(Cell::get);
    COUNTS.with(|c| c.set(OpCounts::default()));
    let result = f();
    let counts = COUNTS.with(|c| c.replace(before));
    (result, counts)
}

/// One f64 lane whose `+ − × ÷ √` are counted (compares, selects and negations are not flops).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Counted(pub(crate) f64);

macro_rules! counted_op {
    ($trait:ident, $method:ident, $field:ident) => {
        impl $trait for Counted {
            type Output = Self;
            #[inline]
            fn $method(self, rhs: Self) -> Self {
                count(|c| &mut c.$field);
                Counted($trait::$method(self.0, rhs.0))
            }
        }
    };
}
counted_op!(Add, add, add);
counted_op!(Sub, sub, add);
counted_op!(Mul, mul, mul);
counted_op!(Div, div, div);

impl Neg for Counted {
    type Output = Self;
    fn neg(self) -> Self {
        Counted(-self.0)
    }
}

impl Lane for Counted {
    type Mask = bool;
    type Cpu = Portable;
    const WIDTH: usize = 1;
    fn splat(_: Portable, x: f64) -> Self {
        Counted(x)
    }
    fn load(_: Portable, values: &[f64]) -> Self {
        Counted(values[0])
    }
    fn store(self, out: &mut [f64]) {
        out[0] = self.0;
    }
    fn load_real(_: Portable, values: &[Real]) -> Self {
        Counted(values[0].widen())
    }
    fn store_real(self, out: &mut [Real]) {
        out[0] = self.0.narrow();
    }
    fn cpu(self) -> Portable {
        Portable
    }
    fn sqrt(self) -> Self {
        count(|c| &mut c.sqrt);
        Counted(self.0.sqrt())
    }
    fn gt(self, other: Self) -> bool {
        self.0 > other.0
    }
    fn select(mask: bool, yes: Self, no: Self) -> Self {
        if mask { yes } else { no }
    }
    fn any(mask: bool) -> bool {
        mask
    }
    fn beyond(self, limit: f64) -> bool {
        self.0.beyond(limit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_counted_and_nothing_else() {
        let x = Counted(2.0);
        let (y, counts) = counted(|| {
            let a = x + x - x; // 2 adds
            let b = a * x / x; // 1 mul, 1 div
            let c = -b.sqrt(); // 1 sqrt, negation free
            Counted::select(c.gt(x), c, x) // compare and select free
        });
        assert_eq!(y, x);
        let expected = OpCounts {
            add: 2,
            mul: 1,
            div: 1,
            sqrt: 1,
        };
        assert_eq!(counts, expected);
        assert_eq!(counts.total(), 5);
        // Counting again starts from zero.
        assert_eq!(counted(|| x * x).1.mul, 1);
    }
}
