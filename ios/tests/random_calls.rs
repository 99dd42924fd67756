//! Seeded random call sequences through the C ABI (`support/random_calls.rs`, which the fuzz
//! target `c_abi` also drives with coverage guidance): every input is a run of up to 64 calls with
//! random arguments on one engine. None may panic or crash, and afterwards the engine must still
//! draw: resumed offscreen, a frame is presented at the size asked for and read back.

use phantogram_ios::ffi::*;

#[path = "support/engine.rs"]
mod engine;
#[path = "support/random_calls.rs"]
mod random_calls;

/// Inputs per run, and the longest (64 calls take at most ~40 bytes each).
const INPUTS: usize = 300;
const MAX_LEN: usize = 1200;

/// xorshift64*: the inputs are the same on every run, so a failure is reproducible.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn bytes(&mut self) -> Vec<u8> {
        let len = (self.next() % (MAX_LEN as u64 + 1)) as usize;
        (0..len).map(|_| (self.next() >> 56) as u8).collect()
    }
}

#[test]
fn random_call_sequences_leave_an_engine_that_draws() {
    let Some(engine) = engine::created_or_skip("the random calls") else {
        return;
    };
    let mut random = Random(0x9e37_79b9_7f4a_7c15);
    for input in 0..INPUTS {
        let data = random.bytes();
        // SAFETY: a live engine, destroyed only below.
        unsafe { random_calls::run(engine, &data) };
        if input % 50 == 49 {
            eprintln!("{} inputs", input + 1);
        }
    }
    // SAFETY: a live handle and valid out pointers.
    unsafe {
        assert_eq!(pg_suspend(engine), PgStatus::Ok);
        assert_eq!(pg_resume_offscreen(engine, 72, 160), PgStatus::Ok);
        let mut presented = 0u8;
        assert_eq!(pg_draw(engine, -1.0, &mut presented), PgStatus::Ok);
        assert_eq!(presented, 1, "no frame after the random calls");
        let mut pixels = vec![0u8; 72 * 160 * 4];
        let (mut w, mut h) = (0u32, 0u32);
        assert_eq!(
            pg_read_frame(engine, pixels.as_mut_ptr(), pixels.len(), &mut w, &mut h),
            PgStatus::Ok
        );
        assert_eq!((w, h), (72, 160));
        assert!(
            pixels.chunks_exact(4).any(|p| p[..3] != [0, 0, 0]),
            "the frame after the random calls is black"
        );
        pg_engine_destroy(engine);
    }
}
