//! The vertices of the paths an estimator samples, for the live book's
//! drawings (`web/`, feature `web`): [`walk`](super::walk::walk) reports
//! where each walk starts and every vertex it reaches.
//!
//! Without the feature the two calls are empty inline functions and the
//! guard a zero-sized type without `Drop`: the native build compiles them
//! away, and its results are the same bits. With it, a thread-local
//! recorder that is off unless `recorded` runs: a run's paths then pay a
//! flag check per vertex and allocate nothing; only the few paths sampled
//! inside `recorded` are written down.
use super::Vector;

/// What [`begin`] returns: while it lives, [`vertex`] adds to its walk.
#[must_use]
pub struct Walk(());

#[cfg(not(feature = "web"))]
mod imp {
    use super::{Vector, Walk};

    #[inline(always)]
    pub fn begin<V: Vector>(_x: V) -> Walk {
        Walk(())
    }

    #[inline(always)]
    pub fn vertex<V: Vector>(_x: V) {}
}

#[cfg(feature = "web")]
mod imp {
    use super::{Vector, Walk};
    use std::cell::{Cell, RefCell};

    /// The vertices written down, and where the recorder is.
    #[derive(Default)]
    pub(super) struct State {
        /// `[path, walk, x, y, z]` per vertex.
        pub points: Vec<[f64; 5]>,
        /// The path being sampled.
        pub path: u32,
        /// Walks started in this path.
        pub walks: u32,
        /// The walks under way, innermost last (a nested walk runs inside
        /// its parent's event).
        pub stack: Vec<u32>,
        /// Most vertices kept (a long random walk is cut).
        pub cap: usize,
    }

    thread_local! {
        pub(super) static ON: Cell<bool> = const { Cell::new(false) };
        pub(super) static STATE: RefCell<State> = RefCell::new(State::default());
    }

    fn push<V: Vector>(s: &mut State, x: V) {
        if s.points.len() < s.cap {
            let mut p = [
                f64::from(s.path),
                f64::from(*s.stack.last().unwrap_or(&0)),
                0.0,
                0.0,
                0.0,
            ];
            for i in 0..V::DIM.min(3) {
                p[2 + i] = x.dot(V::axis(i));
            }
            s.points.push(p);
        }
    }

    #[inline]
    pub fn begin<V: Vector>(x: V) -> Walk {
        if ON.with(Cell::get) {
            STATE.with_borrow_mut(|s| {
                let id = s.walks;
                s.walks += 1;
                s.stack.push(id);
                push(s, x);
            });
        }
        Walk(())
    }

    #[inline]
    pub fn vertex<V: Vector>(x: V) {
        if ON.with(Cell::get) {
            STATE.with_borrow_mut(|s| push(s, x));
        }
    }

    impl Drop for Walk {
        #[inline]
        fn drop(&mut self) {
            if ON.with(Cell::get) {
                STATE.with_borrow_mut(|s| {
                    s.stack.pop();
                });
            }
        }
    }
}

/// A walk starts at `x`: the vertices until the guard drops are its own.
#[inline(always)]
pub fn begin<V: Vector>(x: V) -> Walk {
    imp::begin(x)
}

/// The walk under way reaches `x` (a scattering, reflection or crossing
/// point, or the end of the path).
#[inline(always)]
pub fn vertex<V: Vector>(x: V) {
    imp::vertex(x)
}

/// Runs `sample(i)` for `i` in `0..paths` (each call sampling path `i`
/// with the estimator) and returns the vertices their walks reached, at
/// most `cap`: `[path, walk, x, y, z]` each, `walk` numbering the walks of
/// one path in the order they started (0: the path from the sensor; then
/// its nested walks, or a finite difference's displaced twins), `z` 0 in
/// the plane. Recording changes no random number: the paths are those the
/// estimator samples from the same generator state.
#[cfg(feature = "web")]
pub fn recorded(paths: u32, cap: usize, mut sample: impl FnMut(u32)) -> Vec<[f64; 5]> {
    use imp::{ON, STATE};
    STATE.with_borrow_mut(|s| {
        *s = imp::State {
            cap,
            ..imp::State::default()
        }
    });
    ON.with(|on| on.set(true));
    for i in 0..paths {
        STATE.with_borrow_mut(|s| {
            s.path = i;
            s.walks = 0;
            s.stack.clear();
        });
        sample(i);
    }
    ON.with(|on| on.set(false));
    STATE.with_borrow_mut(|s| std::mem::take(&mut s.points))
}
