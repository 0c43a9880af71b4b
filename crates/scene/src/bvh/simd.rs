//! Eight `f32` lanes for the node tests of `wide.rs`: one AVX register where the build enables
//! AVX2 (the workspace's `.cargo/config.toml` does), an array operated on lane by lane otherwise.
//!
//! Both forms compute the same bits: every operation is the lane-wise IEEE one, and `min`/`max`
//! follow `minps`/`maxps` (the second operand when either is NaN), as glam's `Vec4` does.

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod imp {
    use std::arch::x86_64::{
        __m128i, __m256, __m256i, _CMP_EQ_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm_loadl_epi64,
        _mm256_add_ps, _mm256_and_ps, _mm256_blendv_ps, _mm256_castps_si256, _mm256_castsi256_ps,
        _mm256_cmp_ps, _mm256_cmpeq_epi32, _mm256_cmpgt_epi32, _mm256_cvtepu8_epi32, _mm256_div_ps,
        _mm256_loadu_ps, _mm256_loadu_si256, _mm256_max_ps, _mm256_min_epu32, _mm256_min_ps,
        _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_permute2f128_ps,
        _mm256_permute4x64_epi64, _mm256_permutevar8x32_epi32, _mm256_permutevar8x32_ps,
        _mm256_set1_ps, _mm256_shuffle_epi32, _mm256_shuffle_ps, _mm256_storeu_ps,
        _mm256_storeu_si256, _mm256_sub_ps,
    };

    // SAFETY (every `unsafe` block of this module): the intrinsics need AVX (and AVX2), which the
    // `cfg` of this module guarantees at compile time; the loads and stores go through pointers
    // to `[f32; 8]` arrays owned by the caller.

    /// Eight lanes in one AVX register.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(in crate::bvh) struct F8(__m256);

    impl F8 {
        #[inline(always)]
        pub(in crate::bvh) fn splat(x: f32) -> Self {
            Self(unsafe { _mm256_set1_ps(x) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn from_array(a: [f32; 8]) -> Self {
            Self(unsafe { _mm256_loadu_ps(a.as_ptr()) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn to_array(self) -> [f32; 8] {
            let mut a = [0.0; 8];
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
            a
        }

        #[inline(always)]
        pub(in crate::bvh) fn sub(self, o: Self) -> Self {
            Self(unsafe { _mm256_sub_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn add(self, o: Self) -> Self {
            Self(unsafe { _mm256_add_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn mul(self, o: Self) -> Self {
            Self(unsafe { _mm256_mul_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn div(self, o: Self) -> Self {
            Self(unsafe { _mm256_div_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn min(self, o: Self) -> Self {
            Self(unsafe { _mm256_min_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn max(self, o: Self) -> Self {
            Self(unsafe { _mm256_max_ps(self.0, o.0) })
        }

        /// All-ones lanes where `self <= o` (false for NaN), zero elsewhere.
        #[inline(always)]
        pub(in crate::bvh) fn le(self, o: Self) -> Self {
            Self(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
        }

        /// All-ones lanes where `self < o` (false for NaN), zero elsewhere.
        #[inline(always)]
        pub(in crate::bvh) fn lt(self, o: Self) -> Self {
            Self(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
        }

        /// All-ones lanes where `self == o` (false for NaN), zero elsewhere.
        #[inline(always)]
        pub(in crate::bvh) fn eq(self, o: Self) -> Self {
            Self(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0) })
        }

        /// Bitwise and (of comparison results).
        #[inline(always)]
        pub(in crate::bvh) fn and(self, o: Self) -> Self {
            Self(unsafe { _mm256_and_ps(self.0, o.0) })
        }

        /// Bitwise or.
        #[inline(always)]
        pub(in crate::bvh) fn or(self, o: Self) -> Self {
            Self(unsafe { _mm256_or_ps(self.0, o.0) })
        }

        /// All-ones lanes where the bits of `self` and `o` are equal, zero elsewhere.
        #[inline(always)]
        pub(in crate::bvh) fn eq_bits(self, o: Self) -> Self {
            Self(unsafe {
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }

        /// All-ones lanes where the bits of `self`, read as a signed integer, exceed those of
        /// `o`, zero elsewhere (one cycle, against four for a float comparison).
        #[inline(always)]
        pub(in crate::bvh) fn gt_bits(self, o: Self) -> Self {
            Self(unsafe {
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }

        /// `self` where `mask` (a comparison result) is set, `o` elsewhere.
        #[inline(always)]
        pub(in crate::bvh) fn select(mask: Self, a: Self, b: Self) -> Self {
            Self(unsafe { _mm256_blendv_ps(b.0, a.0, mask.0) })
        }

        #[inline(always)]
        pub(in crate::bvh) fn bitmask(self) -> u32 {
            (unsafe { _mm256_movemask_ps(self.0) }) as u32
        }

        /// The smallest lane, in every lane (a NaN lane may or may not propagate).
        #[inline(always)]
        pub(in crate::bvh) fn min_all(self) -> Self {
            unsafe {
                let v = self.0;
                let m = _mm256_min_ps(v, _mm256_permute2f128_ps::<1>(v, v));
                let m = _mm256_min_ps(m, _mm256_shuffle_ps::<0b01_00_11_10>(m, m));
                Self(_mm256_min_ps(m, _mm256_shuffle_ps::<0b10_11_00_01>(m, m)))
            }
        }

        /// The lane of smallest bits read as an unsigned integer, in every lane: the smallest
        /// lane when every lane is +0, positive, +∞ or a NaN with the sign bit set (which counts
        /// as larger than all of those). Integer minima have a latency of one cycle against four
        /// of `min_ps`, and this minimum sits on the traversal's critical path.
        #[inline(always)]
        pub(in crate::bvh) fn min_all_unsigned(self) -> Self {
            unsafe {
                let v = _mm256_castps_si256(self.0);
                let m = _mm256_min_epu32(v, _mm256_permute4x64_epi64::<0b01_00_11_10>(v));
                let m = _mm256_min_epu32(m, _mm256_shuffle_epi32::<0b01_00_11_10>(m));
                let m = _mm256_min_epu32(m, _mm256_shuffle_epi32::<0b10_11_00_01>(m));
                Self(_mm256_castsi256_ps(m))
            }
        }
    }

    /// Per 8-bit mask, the indices of its set bits in increasing order, one per byte from the
    /// lowest (the unused high bytes are 0).
    static COMPRESS: [u64; 256] = {
        let mut table = [0u64; 256];
        let mut mask = 0;
        while mask < 256 {
            let (mut bits, mut at) = (0u64, 0);
            let mut lane = 0;
            while lane < 8 {
                if mask & (1 << lane) != 0 {
                    bits |= (lane as u64) << (8 * at);
                    at += 1;
                }
                lane += 1;
            }
            table[mask] = bits;
            mask += 1;
        }
        table
    };

    /// Writes the lanes of `refs` and `t` whose bits are set in `mask` (below 2⁸) to the front of
    /// `refs_out` and `t_out`, in lane order; the lanes after them get arbitrary values of the
    /// inputs.
    #[inline(always)]
    pub(in crate::bvh) fn compress(
        mask: u32,
        refs: &[u32; 8],
        t: F8,
        refs_out: &mut [std::mem::MaybeUninit<u32>; 8],
        t_out: &mut [std::mem::MaybeUninit<f32>; 8],
    ) {
        let indices = &COMPRESS[(mask & 0xff) as usize];
        // SAFETY: as for the whole module; `indices` points to 8 readable bytes, `refs` to 32
        // and the outputs to 32 writable bytes each (unaligned accesses).
        unsafe {
            let p =
                _mm256_cvtepu8_epi32(_mm_loadl_epi64((indices as *const u64).cast::<__m128i>()));
            let r = _mm256_loadu_si256(refs.as_ptr().cast::<__m256i>());
            _mm256_storeu_si256(
                refs_out.as_mut_ptr().cast::<__m256i>(),
                _mm256_permutevar8x32_epi32(r, p),
            );
            _mm256_storeu_ps(
                t_out.as_mut_ptr().cast::<f32>(),
                _mm256_permutevar8x32_ps(t.0, p),
            );
        }
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
mod imp {
    /// Eight lanes as an array, operated on lane by lane (comparison results as all-ones or zero
    /// bit patterns).
    #[derive(Clone, Copy, Debug)]
    pub(in crate::bvh) struct F8([f32; 8]);

    const SET: f32 = f32::from_bits(u32::MAX);

    impl F8 {
        #[inline(always)]
        fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
            Self(std::array::from_fn(|i| f(self.0[i], o.0[i])))
        }

        #[inline(always)]
        fn flag(b: bool) -> f32 {
            if b { SET } else { 0.0 }
        }

        #[inline(always)]
        pub(in crate::bvh) fn splat(x: f32) -> Self {
            Self([x; 8])
        }

        #[inline(always)]
        pub(in crate::bvh) fn from_array(a: [f32; 8]) -> Self {
            Self(a)
        }

        #[inline(always)]
        pub(in crate::bvh) fn to_array(self) -> [f32; 8] {
            self.0
        }

        #[inline(always)]
        pub(in crate::bvh) fn sub(self, o: Self) -> Self {
            self.zip(o, |a, b| a - b)
        }

        #[inline(always)]
        pub(in crate::bvh) fn add(self, o: Self) -> Self {
            self.zip(o, |a, b| a + b)
        }

        #[inline(always)]
        pub(in crate::bvh) fn mul(self, o: Self) -> Self {
            self.zip(o, |a, b| a * b)
        }

        #[inline(always)]
        pub(in crate::bvh) fn div(self, o: Self) -> Self {
            self.zip(o, |a, b| a / b)
        }

        /// As `minps`: the second operand unless the first is smaller.
        #[inline(always)]
        pub(in crate::bvh) fn min(self, o: Self) -> Self {
            self.zip(o, |a, b| if a < b { a } else { b })
        }

        /// As `maxps`: the second operand unless the first is larger.
        #[inline(always)]
        pub(in crate::bvh) fn max(self, o: Self) -> Self {
            self.zip(o, |a, b| if a > b { a } else { b })
        }

        #[inline(always)]
        pub(in crate::bvh) fn le(self, o: Self) -> Self {
            self.zip(o, |a, b| Self::flag(a <= b))
        }

        #[inline(always)]
        pub(in crate::bvh) fn lt(self, o: Self) -> Self {
            self.zip(o, |a, b| Self::flag(a < b))
        }

        #[inline(always)]
        pub(in crate::bvh) fn eq(self, o: Self) -> Self {
            self.zip(o, |a, b| Self::flag(a == b))
        }

        #[inline(always)]
        pub(in crate::bvh) fn and(self, o: Self) -> Self {
            self.zip(o, |a, b| f32::from_bits(a.to_bits() & b.to_bits()))
        }

        #[inline(always)]
        pub(in crate::bvh) fn or(self, o: Self) -> Self {
            self.zip(o, |a, b| f32::from_bits(a.to_bits() | b.to_bits()))
        }

        #[inline(always)]
        pub(in crate::bvh) fn eq_bits(self, o: Self) -> Self {
            self.zip(o, |a, b| Self::flag(a.to_bits() == b.to_bits()))
        }

        #[inline(always)]
        pub(in crate::bvh) fn gt_bits(self, o: Self) -> Self {
            self.zip(o, |a, b| {
                Self::flag(a.to_bits() as i32 > b.to_bits() as i32)
            })
        }

        #[inline(always)]
        pub(in crate::bvh) fn select(mask: Self, a: Self, b: Self) -> Self {
            Self(std::array::from_fn(|i| {
                if mask.0[i].to_bits() >> 31 != 0 {
                    a.0[i]
                } else {
                    b.0[i]
                }
            }))
        }

        #[inline(always)]
        pub(in crate::bvh) fn bitmask(self) -> u32 {
            (0..8).fold(0, |m, i| m | (self.0[i].to_bits() >> 31) << i)
        }

        #[inline(always)]
        pub(in crate::bvh) fn min_all(self) -> Self {
            Self::splat(
                self.0
                    .iter()
                    .fold(f32::INFINITY, |m, &x| if x < m { x } else { m }),
            )
        }

        #[inline(always)]
        pub(in crate::bvh) fn min_all_unsigned(self) -> Self {
            Self::splat(f32::from_bits(
                self.0.iter().map(|x| x.to_bits()).min().unwrap_or(u32::MAX),
            ))
        }
    }

    /// Writes the lanes of `refs` and `t` whose bits are set in `mask` (below 2⁸) to the front of
    /// `refs_out` and `t_out`, in lane order (the AVX form also writes the lanes after them).
    #[inline(always)]
    pub(in crate::bvh) fn compress(
        mask: u32,
        refs: &[u32; 8],
        t: F8,
        refs_out: &mut [std::mem::MaybeUninit<u32>; 8],
        t_out: &mut [std::mem::MaybeUninit<f32>; 8],
    ) {
        for (at, lane) in (0..8).filter(|&lane| mask & (1 << lane) != 0).enumerate() {
            refs_out[at].write(refs[lane]);
            t_out[at].write(t.0[lane]);
        }
    }
}

pub(super) use imp::{F8, compress};
