//! Points in time as the history writes them (a commit's committer date from git's `%cI`, a
//! measurement's UTC start): read to one UTC instant, so that two dates compare by when they
//! happened, not by their text. Git keeps the committer's own offset, so
//! `2026-12-01T23:00:00-05:00` is after `2026-12-02T02:00:00Z` although its text sorts first.

/// An instant, UTC: seconds since 1970-01-01T00:00:00Z and the nanoseconds past them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Instant {
    /// Whole seconds since the Unix epoch (negative before it).
    pub secs: i64,
    /// Nanoseconds past `secs`, below 1e9.
    pub nanos: u32,
}

/// The instant `text` names, `None` when it is not a time this reader knows. Accepted: an RFC
/// 3339 / ISO 8601 date and time, `YYYY-MM-DDTHH:MM[:SS[.fraction]]` (`T`, `t` or a space
/// between them) followed by `Z`, `z`, `±HH:MM`, `±HHMM` or `±HH` (none: UTC), or a date alone,
/// `YYYY-MM-DD` (its midnight, UTC).
pub fn parse(text: &str) -> Option<Instant> {
    let t = text.trim().as_bytes();
    let (date, rest) = t.split_at_checked(10)?;
    let days = civil_days(date)?;
    if rest.is_empty() {
        return Some(Instant {
            secs: days * 86_400,
            nanos: 0,
        });
    }
    let (sep, rest) = rest.split_first()?;
    if !matches!(sep, b'T' | b't' | b' ') {
        return None;
    }
    let (hour, rest) = number(rest, 2)?;
    let rest = rest.strip_prefix(b":")?;
    let (minute, mut rest) = number(rest, 2)?;
    let (mut second, mut nanos) = (0, 0);
    if let Some(r) = rest.strip_prefix(b":") {
        (second, rest) = number(r, 2)?;
        if let Some(r) = rest.strip_prefix(b".") {
            let digits = r.iter().take_while(|b| b.is_ascii_digit()).count();
            if digits == 0 {
                return None;
            }
            // Nanoseconds: the first nine digits, the rest below what any clock here reads.
            for i in 0..9 {
                nanos = nanos * 10 + r.get(i).filter(|_| i < digits).map_or(0, |b| b - b'0') as u32;
            }
            rest = &r[digits..];
        }
    }
    // 60 is a leap second: read as the next minute's first.
    if hour > 23 || minute > 59 || second > 60 {
        return None;
    }
    let offset = offset_s(rest)?;
    let secs = days * 86_400 + (hour * 3600 + minute * 60 + second) as i64 - offset;
    Some(Instant { secs, nanos })
}

/// Days since 1970-01-01 of a `YYYY-MM-DD` date (Howard Hinnant's `days_from_civil`); `None`
/// for any other text or a day the month does not have.
fn civil_days(date: &[u8]) -> Option<i64> {
    let (year, rest) = number(date, 4)?;
    let (month, rest) = number(rest.strip_prefix(b"-")?, 2)?;
    let (day, rest) = number(rest.strip_prefix(b"-")?, 2)?;
    let leap = year % 4 == 0 && (year % 100 != 0 || year % 400 == 0);
    let month_days = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    if !rest.is_empty() || !(1..=12).contains(&month) || day < 1 || day > month_days[month - 1] {
        return None;
    }
    let (y, m, d) = (year as i64 - (month <= 2) as i64, month as i64, day as i64);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some(era * 146_097 + doe - 719_468)
}

/// The zone's offset east of UTC in seconds: `Z`, `z`, `±HH:MM`, `±HHMM`, `±HH`, or nothing
/// (UTC).
fn offset_s(zone: &[u8]) -> Option<i64> {
    let sign = match zone.first() {
        None => return Some(0),
        Some(b'Z' | b'z') if zone.len() == 1 => return Some(0),
        Some(b'+') => 1,
        Some(b'-') => -1,
        _ => return None,
    };
    let (hours, rest) = number(&zone[1..], 2)?;
    let minutes = match rest {
        [] => 0,
        [b':', m @ ..] | m => match number(m, 2)? {
            (m, []) => m,
            _ => return None,
        },
    };
    (hours <= 23 && minutes <= 59).then(|| sign * (hours * 3600 + minutes * 60) as i64)
}

/// The number written by the first `digits` bytes of `text` (ASCII digits only), and the rest.
fn number(text: &[u8], digits: usize) -> Option<(usize, &[u8])> {
    let (head, rest) = text.split_at_checked(digits)?;
    head.iter()
        .try_fold(0usize, |n, b| {
            b.is_ascii_digit().then(|| n * 10 + (b - b'0') as usize)
        })
        .map(|n| (n, rest))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str) -> Instant {
        parse(text).unwrap_or_else(|| panic!("{text} is not read"))
    }

    #[test]
    fn offsets_are_read_to_utc() {
        assert_eq!(at("1970-01-01T00:00:00Z"), Instant { secs: 0, nanos: 0 });
        assert_eq!(at("1970-01-01"), at("1970-01-01T00:00:00+00:00"));
        assert_eq!(at("2026-12-01T23:00:00-05:00"), at("2026-12-02T04:00:00Z"));
        assert_eq!(at("2026-12-01T23:00-05:00"), at("2026-12-02T04:00Z"));
        assert_eq!(at("2026-12-02T09:30:00+0530"), at("2026-12-02T04:00:00Z"));
        assert_eq!(at("2026-12-02 04:00:00+00"), at("2026-12-02t04:00:00z"));
        assert!(at("2026-12-01T23:00:00-05:00") > at("2026-12-02T02:00:00Z"));
        // 2000 is a leap year, 2100 is not; days count across eras.
        assert_eq!(at("2000-03-01").secs - at("2000-02-28").secs, 2 * 86_400);
        assert!(parse("2100-02-29").is_none());
        assert_eq!(at("2026-12-06T17:02:56Z").secs, 1_796_576_576);
        assert_eq!(at("1969-12-31T23:59:59Z").secs, -1);
    }

    #[test]
    fn fractions_keep_their_order() {
        let a = at("2026-12-01T10:00:00.25Z");
        assert_eq!(a.nanos, 250_000_000);
        assert!(a < at("2026-12-01T10:00:00.250000001Z"));
        assert!(a > at("2026-12-01T10:00:00Z"));
    }

    #[test]
    fn what_is_not_a_time_is_none() {
        for bad in [
            "",
            "yesterday",
            "2026-13-01",
            "2026-02-30",
            "2026-12-01T24:00:00Z",
            "2026-12-01T10:60:00Z",
            "2026-12-01T10:00:00.Z",
            "2026-12-01T10:00:00+25:00",
            "2026-12-01T10:00:00 UTC",
            "2026-12-01T10",
            "2026-12-01X10:00",
            "２０２６-12-01",
            "+2026-12-01",
        ] {
            assert!(parse(bad).is_none(), "{bad}");
        }
    }
}
