// Leaping sample by sample (DVR with RC-s or RC-s-df, whose rays end early at different
// samples): a lookup where the sample passes the region the last one found can matter (a leaf
// block; with the distance field, the cube of such blocks around it). Block runs measured slower
// for DVR (docs/benchmarks/nvidia-h200-leap-walk, nvidia-h200-two-sided).

// Takes or leaps grid samples `first` .. `end` − 1 of `ray` into `acc`: the whole ray, or with
// RAY_SPLIT one part of it. Returns the sample it stopped at (past `end` where a leap overshot).
fn march_samples(acc: ptr<function, Acc>, tally: ptr<function, Tally>, ray: Ray, first: u32, end: u32) -> u32 {
    let entry = ray.entry;
    var leap = leap_ray(entry, ray.box_per_mm, ray.offset);
    var k = first;
    loop {
        if k >= end || !part_matters() {
            break;
        }
        let t = sample_distance(ray, k);
        let p = entry + ray.box_per_mm * t;
        let next = leap_from(&leap, p, k, *acc, tally);
#ifndef PREINTEGRATED
        if next != k {
            tally_leap(tally, min(next, end) - k);
            k = next;
            continue;
        }
#endif
        let result = acc_sample(acc, ray, k, t, p, inner_value(p));
        tally_sample(tally, result);
        if (result & SAMPLE_STOP) != 0u {
            break;
        }
#ifdef PREINTEGRATED
        if next != k {
            // Sample k closed the segment into the empty region; the segments inside it add
            // nothing, and the region's last sample starts the segment out of it.
            let last = min(next, end) - 1u;
            if last > k {
                let t_last = sample_distance(ray, last);
                let p_last = entry + ray.box_per_mm * t_last;
                acc_resume(acc, t_last, p_last, inner_value(p_last));
            }
            // Samples k + 1 .. next − 1 (sample k was taken; the resumed one is not counted
            // as a sample, as it is only read, not classified).
            tally_leap(tally, min(next, end) - k - 1u);
            k = next;
            continue;
        }
#endif
        k += 1u;
    }
    return k;
}
