//! Unit tests of the shard partition, I/N parsing and state packing.
use super::*;

#[test]
fn shards_partition_the_blocks_in_order() {
    for total in [0, 1, 2, 5, 16, 17, 1000] {
        for n in [1, 2, 3, 4, 7, 16, 40] {
            let mut next = 0;
            for i in 1..=n {
                let r = Shard::new(i, n).unwrap().blocks(total);
                assert_eq!(r.start, next, "{i}/{n} of {total}");
                assert!(r.end >= r.start);
                // Nearly equal shares.
                assert!(r.end - r.start <= total.div_ceil(n));
                next = r.end;
            }
            assert_eq!(next, total);
        }
    }
}

#[test]
fn shards_parse_from_i_slash_n() {
    assert_eq!(
        "2/4".parse::<Shard>().unwrap(),
        Shard { index: 2, count: 4 }
    );
    assert_eq!(" 1 / 1 ".parse::<Shard>().unwrap(), Shard::WHOLE);
    for bad in ["0/4", "5/4", "4", "a/4", "1/0", "1/2/3", "-1/4", ""] {
        let e = bad.parse::<Shard>().unwrap_err().to_string();
        assert!(e.contains("I/N") || e.contains("1 ≤ I ≤ N"), "{bad}: {e}");
    }
}

#[test]
fn packing_keeps_every_bit() {
    let m = Moments {
        n: 7,
        nonzero: 3,
        mean: -0.1,
        m2: f64::NAN,
        m3: f64::INFINITY,
        m4: f64::MIN_POSITIVE / 2.0,
        max_abs: -0.0,
        sum_abs: 1e300,
        jumps: Some(0),
    };
    let back = unpack(&pack(&m));
    assert_eq!(pack(&back), pack(&m));
    assert_eq!(back.jumps, Some(0));
    let untracked = Moments { jumps: None, ..m };
    assert_eq!(unpack(&pack(&untracked)).jumps, None);
    assert!(back.m2.is_nan() && back.m3 == f64::INFINITY);
    assert!(back.max_abs.is_sign_negative());
}
