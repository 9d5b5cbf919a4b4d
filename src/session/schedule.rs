//! The order of a progressive viewport render, as Cycles' viewport: one sample per pixel at
//! a coarse pixel size, halved pass by pass down to the viewport's pixel size, then rounds of
//! samples at that pixel size.

/// Cycles' start resolution divider: halve the image until it has at most `resolution²`
/// pixels (`resolution` 0: no reduced start), at least `pixel_size`.
pub fn start_divider(width: u32, height: u32, resolution: u32, pixel_size: u32) -> u32 {
    let pixel_size = pixel_size.max(1);
    if resolution == 0 {
        return pixel_size;
    }
    let (mut w, mut h, mut d) = (width as u64, height as u64, 1u32);
    let target = resolution as u64 * resolution as u64;
    while w * h > target && d < 1 << 16 {
        w = (w / 2).max(1);
        h = (h / 2).max(1);
        d *= 2;
    }
    d.max(pixel_size)
}

/// The sample count the next round at full resolution ends at, after `done` samples, for a
/// target of `target` (0 = no end): 1, 2, 4, 8, 16, then 16 more each round. `None` when
/// the target is reached.
pub fn next_round(done: u32, target: u32) -> Option<u32> {
    if target != 0 && done >= target {
        return None;
    }
    let next = if done < 16 {
        (done * 2).max(1)
    } else {
        done.saturating_add(16)
    };
    Some(if target == 0 { next } else { next.min(target) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dividers_follow_cycles() {
        // 1920x1080 halved five times is 60x33 (1980 pixels <= 64²): divider 32.
        assert_eq!(start_divider(1920, 1080, 64, 1), 32);
        assert_eq!(start_divider(64, 64, 64, 1), 1);
        assert_eq!(start_divider(65, 64, 64, 1), 2);
        assert_eq!(start_divider(100, 100, 0, 2), 2);
        assert_eq!(start_divider(100, 100, 64, 4), 4);
    }

    #[test]
    fn rounds_double_then_step_and_stop_at_the_target() {
        let mut v = Vec::new();
        let mut done = 0;
        while let Some(n) = next_round(done, 40) {
            v.push(n);
            done = n;
        }
        assert_eq!(v, [1, 2, 4, 8, 16, 32, 40]);
        assert_eq!(next_round(48, 0), Some(64));
        assert_eq!(next_round(3, 3), None);
    }
}
