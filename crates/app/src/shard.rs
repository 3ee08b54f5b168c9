//! Which samples a render renders: all of them, `--samples START..END`, or part I of N
//! (`--shard I/N`, or `--shard auto` from a job array's environment).

use std::ops::Range;

use anyhow::{Context, bail};

/// `--shard`: a part given on the command line, or one the job engine's environment names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shard {
    /// Part `index` (from 0) of `count`.
    Part {
        /// Which part, from 0.
        index: u32,
        /// How many parts.
        count: u32,
    },
    /// From `SLURM_ARRAY_TASK_ID`, `JOB_COMPLETION_INDEX` or `AWS_BATCH_JOB_ARRAY_INDEX`.
    Auto,
}

/// A `--shard` value that is neither `I/N` with I < N nor `auto`.
#[derive(Debug, thiserror::Error)]
#[error("{0:?} is not a shard: `I/N` with 0 <= I < N (part I of N, from 0), or `auto`")]
pub struct BadShard(String);

/// Parses `--shard`.
pub fn parse_shard(text: &str) -> Result<Shard, BadShard> {
    if text == "auto" {
        return Ok(Shard::Auto);
    }
    let bad = || BadShard(text.to_owned());
    let (index, count) = text.split_once('/').ok_or_else(bad)?;
    let (index, count) = (
        index.trim().parse::<u32>().map_err(|_| bad())?,
        count.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if index >= count {
        return Err(bad());
    }
    Ok(Shard::Part { index, count })
}

/// A `--samples` value that is not `START..END` with START < END.
#[derive(Debug, thiserror::Error)]
#[error("{0:?} is not a sample range: `START..END`, sample indices with START < END")]
pub struct BadRange(String);

/// Parses `--samples START..END`.
pub fn parse_range(text: &str) -> Result<Range<u32>, BadRange> {
    let bad = || BadRange(text.to_owned());
    let (start, end) = text.split_once("..").ok_or_else(bad)?;
    let (start, end) = (
        start.trim().parse::<u32>().map_err(|_| bad())?,
        end.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if start >= end {
        return Err(bad());
    }
    Ok(start..end)
}

impl Shard {
    /// The part this process renders: `Auto` reads the job array's index from `env` (and
    /// its size, or `count` where the engine does not give one).
    pub fn resolve(
        self,
        count: Option<u32>,
        env: impl Fn(&str) -> Option<String>,
    ) -> anyhow::Result<(u32, u32)> {
        let (index, count) = match self {
            Shard::Part { index, count } => (index, count),
            Shard::Auto => auto(count, env)?,
        };
        if count == 0 || index >= count {
            bail!("shard {index} of {count}: the index must be below the count");
        }
        Ok((index, count))
    }
}

/// The index and count a job array's environment gives: Slurm's array task (relative to
/// the array's first index), a Kubernetes Indexed Job's completion index or an AWS Batch
/// array index (both with `count`).
fn auto(count: Option<u32>, env: impl Fn(&str) -> Option<String>) -> anyhow::Result<(u32, u32)> {
    let number = |name: &str| -> anyhow::Result<Option<u32>> {
        env(name)
            .map(|v| {
                v.trim()
                    .parse::<u32>()
                    .with_context(|| format!("${name} = {v:?} is not a whole number"))
            })
            .transpose()
    };
    if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
        let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
        let count = match (count, number("SLURM_ARRAY_TASK_COUNT")?) {
            (Some(count), _) | (None, Some(count)) => count,
            (None, None) => {
                bail!("--shard auto: $SLURM_ARRAY_TASK_COUNT is unset; give --shard-count")
            }
        };
        let index = id.checked_sub(min).with_context(|| {
            format!("$SLURM_ARRAY_TASK_ID {id} is below $SLURM_ARRAY_TASK_MIN {min}")
        })?;
        return Ok((index, count));
    }
    for name in ["JOB_COMPLETION_INDEX", "AWS_BATCH_JOB_ARRAY_INDEX"] {
        if let Some(index) = number(name)? {
            let count = count.with_context(|| {
                format!(
                    "--shard auto found ${name} but not the number of parts: give --shard-count"
                )
            })?;
            return Ok((index, count));
        }
    }
    bail!(
        "--shard auto: no job array index in the environment ($SLURM_ARRAY_TASK_ID, \
         $JOB_COMPLETION_INDEX or $AWS_BATCH_JOB_ARRAY_INDEX)"
    )
}

/// Part `index` of `count` of the sample indices `0 .. spp`: contiguous, sizes differing by
/// at most one, together all of them.
pub fn part_of(index: u32, count: u32, spp: u32) -> Range<u32> {
    let at = |i: u32| (u64::from(spp) * u64::from(i) / u64::from(count)) as u32;
    at(index)..at(index + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_the_samples_once() {
        for count in [1, 2, 3, 7, 64] {
            let parts: Vec<_> = (0..count).map(|i| part_of(i, count, 64)).collect();
            assert_eq!(parts[0].start, 0);
            assert_eq!(parts[count as usize - 1].end, 64);
            for pair in parts.windows(2) {
                assert_eq!(pair[0].end, pair[1].start);
            }
        }
        assert_eq!(part_of(2, 3, 10), 6..10);
    }

    #[test]
    fn shards_parse_and_read_job_arrays() {
        assert_eq!(
            parse_shard("2/7").unwrap(),
            Shard::Part { index: 2, count: 7 }
        );
        for bad in ["7/7", "1", "a/2", "-1/2", "1/0"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_range("16..48").unwrap(), 16..48);
        for bad in ["5..5", "9..2", "1-3", "..4"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
        fn env<'a>(vars: &'a [(&str, &str)]) -> impl Fn(&str) -> Option<String> + 'a {
            move |name: &str| {
                vars.iter()
                    .find(|(n, _)| *n == name)
                    .map(|(_, v)| v.to_string())
            }
        }
        let slurm = [
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "4"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        assert_eq!(Shard::Auto.resolve(None, env(&slurm)).unwrap(), (1, 4));
        let k8s = [("JOB_COMPLETION_INDEX", "3")];
        assert_eq!(Shard::Auto.resolve(Some(8), env(&k8s)).unwrap(), (3, 8));
        let err = Shard::Auto.resolve(None, env(&k8s)).unwrap_err();
        assert!(err.to_string().contains("--shard-count"), "{err}");
        let aws = [("AWS_BATCH_JOB_ARRAY_INDEX", "9")];
        assert!(Shard::Auto.resolve(Some(4), env(&aws)).is_err(), "9 of 4");
        let err = Shard::Auto.resolve(None, env(&[])).unwrap_err();
        assert!(err.to_string().contains("no job array index"), "{err}");
    }
}
