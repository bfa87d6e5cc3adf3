//! Large scratch buffers kept from one fit to the next on the same thread.
//!
//! A fit with the Gram matrix needs a few megabytes of scratch that it frees at its end (the
//! Gram matrix, the kernel's packing buffer). Freed, they go back to the C allocator, which
//! may return them to the kernel (glibc trims the top of its heap once more than a threshold
//! is free there): the next fit then touches fresh pages again, one page fault per 4 KiB
//! (2.6 ms of the 21 ms of a 5000 x 500 fit run after other sizes). Kept here instead, the
//! pages stay mapped. At most [`KEEP`] buffers and [`KEEP_BYTES`] in all are kept per thread;
//! a larger buffer is simply freed.

use std::cell::RefCell;

/// Buffers kept per thread.
const KEEP: usize = 4;
/// Bytes kept per thread, at most.
const KEEP_BYTES: usize = 32 << 20;

thread_local! {
    static POOL: RefCell<Vec<Vec<f64>>> = const { RefCell::new(Vec::new()) };
}

/// A buffer of `len` zeros: the smallest kept buffer with room for `len` values if there is
/// one, else a new one.
pub(crate) fn zeroed(len: usize) -> Vec<f64> {
    let kept = POOL
        .try_with(|pool| {
            let mut pool = pool.try_borrow_mut().ok()?;
            let pos = pool
                .iter()
                .enumerate()
                .filter(|(_, b)| b.capacity() >= len)
                .min_by_key(|(_, b)| b.capacity())
                .map(|(i, _)| i)?;
            Some(pool.swap_remove(pos))
        })
        .ok()
        .flatten();
    match kept {
        Some(mut b) => {
            b.clear();
            b.resize(len, 0.0);
            b
        }
        None => vec![0.0; len],
    }
}

/// Gives a buffer back for a later [`zeroed`] on this thread (or frees it, when the pool is
/// full: the smallest buffers are the ones let go).
pub(crate) fn recycle(buf: Vec<f64>) {
    if buf.capacity() == 0 || buf.capacity() * size_of::<f64>() > KEEP_BYTES {
        return;
    }
    // (a pool that cannot be reached, during the thread's teardown, frees the buffer)
    let _ = POOL.try_with(|pool| {
        if let Ok(mut pool) = pool.try_borrow_mut() {
            pool.push(buf);
            pool.sort_by_key(|b| std::cmp::Reverse(b.capacity()));
            let mut bytes = 0;
            let mut keep = 0;
            for b in pool.iter() {
                if keep == KEEP || bytes + b.capacity() * size_of::<f64>() > KEEP_BYTES {
                    break;
                }
                bytes += b.capacity() * size_of::<f64>();
                keep += 1;
            }
            pool.truncate(keep);
        }
    });
}

/// `f64`s in a 64-byte line: a vector of AVX-512.
const LINE: usize = 8;

/// A zeroed buffer from the pool whose first value starts a 64-byte cache line (a vector
/// load from it, at a multiple of 8 values, never straddles two lines: an unaligned 512-bit
/// load that does costs two of the core's load slots), given back to the pool when dropped.
pub(crate) struct Aligned {
    buf: Vec<f64>,
    off: usize,
    len: usize,
}

impl Aligned {
    /// `len` zeros, line-aligned.
    pub(crate) fn zeroed(len: usize) -> Self {
        let buf = zeroed(len + LINE - 1);
        // (the address is only looked at, never made into a pointer again)
        let misalign = (buf.as_ptr() as usize / size_of::<f64>()) % LINE;
        let off = (LINE - misalign) % LINE;
        Aligned { buf, off, len }
    }

    /// No room at all (no buffer taken from the pool).
    pub(crate) fn empty() -> Self {
        Aligned {
            buf: Vec::new(),
            off: 0,
            len: 0,
        }
    }

    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.buf[self.off..self.off + self.len]
    }

    pub(crate) fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.buf[self.off..self.off + self.len]
    }
}

impl Drop for Aligned {
    fn drop(&mut self) {
        recycle(std::mem::take(&mut self.buf));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recycled_buffer_comes_back_zeroed_and_the_pool_stays_bounded() {
        let mut b = zeroed(1000);
        b.iter_mut().for_each(|v| *v = 7.0);
        let ptr = b.as_ptr();
        recycle(b);
        let c = zeroed(900);
        assert_eq!(c.as_ptr(), ptr, "the kept buffer is reused");
        assert_eq!(c.len(), 900);
        assert!(c.iter().all(|&v| v == 0.0));
        recycle(c);
        for _ in 0..10 {
            recycle(vec![1.0; 10]);
        }
        // too large to keep
        recycle(Vec::with_capacity(KEEP_BYTES / 8 + 1));
        let mut a = Aligned::zeroed(333);
        assert_eq!(a.as_slice().len(), 333);
        assert_eq!(a.as_slice().as_ptr() as usize % 64, 0);
        assert!(a.as_slice().iter().all(|&v| v == 0.0));
        a.as_mut_slice()[332] = 1.0;
        drop(a);
        POOL.with_borrow(|pool| {
            assert!(pool.len() <= KEEP);
            assert!(pool.iter().map(|b| b.capacity() * 8).sum::<usize>() <= KEEP_BYTES);
            assert!(
                pool.iter().any(|b| b.capacity() >= 1000),
                "the large one kept"
            );
        });
    }
}
