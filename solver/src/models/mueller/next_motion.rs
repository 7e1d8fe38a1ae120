//! [`NextMotion`]: where Müller's force pass writes each particle's position and velocity at
//! the end of the step, while the other particles' forces still read the current ones.

use crate::solver::model::Scratch;
use crate::sph::neighbors::list::written_zeros;
use crate::sph::state::State;

/// Positions and velocities at the end of the step being taken. The force pass moves each
/// particle as soon as its force is known (one pass instead of a force pass and an update
/// pass, so one barrier less per step), which is sound only if no other particle's force reads
/// the moved values: they go here, and the state takes them ([`NextMotion::swap_into`]) once
/// the pass has finished. Between steps the arrays hold the step before's positions and
/// velocities, which nothing reads.
#[derive(Debug, Clone)]
pub struct NextMotion {
    /// x of every particle, px.
    pub x: Vec<f64>,
    /// y of every particle, px.
    pub y: Vec<f64>,
    /// Velocity x of every particle.
    pub vx: Vec<f64>,
    /// Velocity y of every particle.
    pub vy: Vec<f64>,
}

impl NextMotion {
    /// Arrays of `n` particles, written when allocated (so that the first timed pass does not
    /// pay for the kernel mapping fresh pages).
    pub fn new(n: usize) -> NextMotion {
        NextMotion {
            x: written_zeros(n),
            y: written_zeros(n),
            vx: written_zeros(n),
            vy: written_zeros(n),
        }
    }

    /// Makes these the state's positions and velocities, and the state's old ones these.
    pub fn swap_into(&mut self, s: &mut State) {
        std::mem::swap(&mut self.x, &mut s.x);
        std::mem::swap(&mut self.y, &mut s.y);
        std::mem::swap(&mut self.vx, &mut s.vx);
        std::mem::swap(&mut self.vy, &mut s.vy);
    }
}

impl Scratch for NextMotion {
    fn heap_bytes(&self) -> usize {
        8 * (self.x.capacity() + self.y.capacity() + self.vx.capacity() + self.vy.capacity())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_swap_hands_the_state_the_new_motion_and_keeps_the_old() {
        let mut s =
            State::from_kinematics(vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0; 2], vec![6.0; 2]);
        let mut next = NextMotion::new(2);
        next.x.copy_from_slice(&[7.0, 8.0]);
        next.vy.copy_from_slice(&[9.0, 10.0]);
        next.swap_into(&mut s);
        assert_eq!(
            (s.x.as_slice(), s.y.as_slice()),
            (&[7.0, 8.0][..], &[0.0; 2][..])
        );
        assert_eq!(
            (s.vx.as_slice(), s.vy.as_slice()),
            (&[0.0; 2][..], &[9.0, 10.0][..])
        );
        assert_eq!((next.x, next.vy), (vec![1.0, 2.0], vec![6.0; 2]));
        assert_eq!(NextMotion::new(3).heap_bytes(), 8 * 4 * 3);
    }
}
