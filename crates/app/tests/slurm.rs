//! A real job engine: a one-node Slurm cluster started on this machine (munged, slurmctld,
//! slurmd, with a configuration that needs neither systemd nor cgroups) runs
//! `examples/slurm/submit.sh`: a 4-task job array renders the parts, a merge job that depends
//! on it sums them, and the merged image must equal a single-machine render byte for byte.
//! Needs Debian's `slurm-wlm` and `munge` (`.ci/run` installs them) and root, as CI has.

use std::io::Read as _;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Longest wait for the cluster to come up and for the jobs to finish.
const TIMEOUT: Duration = Duration::from_secs(300);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The path of `program`, or a panic saying what to install.
fn require(program: &str) -> PathBuf {
    let output = Command::new("sh")
        .args([
            "-c",
            &format!("command -v {program} || ls /usr/sbin/{program}"),
        ])
        .output()
        .unwrap();
    let path = String::from_utf8_lossy(&output.stdout).trim().to_owned();
    assert!(
        output.status.success() && !path.is_empty(),
        "{program} is missing: install the Debian packages slurm-wlm and munge (.ci/run does)"
    );
    PathBuf::from(path.lines().next().unwrap())
}

/// A TCP port nobody listens on now.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// The cluster's daemons, stopped by their process ids on drop.
struct Cluster {
    dir: tempfile::TempDir,
    daemons: Vec<Child>,
}

impl Cluster {
    fn start() -> Self {
        let (munged, slurmctld, slurmd) =
            (require("munged"), require("slurmctld"), require("slurmd"));
        require("sbatch");
        let is_root = Command::new("id").arg("-u").output().unwrap().stdout == b"0\n";
        assert!(
            is_root,
            "the Slurm test starts daemons as root (CI runs as root)"
        );
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().to_str().unwrap().to_owned();
        // A fresh munge key, readable by root only.
        let key = dir.path().join("munge.key");
        let mut bytes = vec![0u8; 1024];
        std::fs::File::open("/dev/urandom")
            .unwrap()
            .read_exact(&mut bytes)
            .unwrap();
        std::fs::write(&key, &bytes).unwrap();
        std::fs::set_permissions(&key, std::os::unix::fs::PermissionsExt::from_mode(0o400))
            .unwrap();
        let (ctld_port, slurmd_port) = (free_port(), free_port());
        let conf = format!(
            "ClusterName=pathlight\n\
             SlurmctldHost=localhost(127.0.0.1)\n\
             SlurmUser=root\nSlurmdUser=root\n\
             AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={d}/munge.sock\n\
             SlurmctldPort={ctld_port}\nSlurmdPort={slurmd_port}\n\
             StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\n\
             SlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
             SlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n\
             SchedulerType=sched/builtin\nSelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n\
             ReturnToService=2\nMpiDefault=none\n\
             NodeName=pathlight-node NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN\n\
             PartitionName=debug Nodes=pathlight-node Default=YES MaxTime=INFINITE State=UP\n"
        );
        for sub in ["state", "spool"] {
            std::fs::create_dir(dir.path().join(sub)).unwrap();
        }
        std::fs::write(dir.path().join("slurm.conf"), conf).unwrap();
        let mut cluster = Self {
            dir,
            daemons: Vec::new(),
        };
        let spawn = |program: &Path, args: Vec<String>| {
            Command::new(program)
                .args(args)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap_or_else(|err| panic!("{}: {err}", program.display()))
        };
        cluster.daemons.push(spawn(
            &munged,
            vec![
                "--foreground".into(),
                "--force".into(),
                format!("--socket={d}/munge.sock"),
                format!("--key-file={d}/munge.key"),
                format!("--pid-file={d}/munged.pid"),
                format!("--log-file={d}/munged.log"),
                format!("--seed-file={d}/munge.seed"),
            ],
        ));
        cluster.wait_until("munged's socket", || {
            Path::new(&format!("{d}/munge.sock")).exists()
        });
        let conf = format!("{d}/slurm.conf");
        cluster.daemons.push(spawn(
            &slurmctld,
            vec!["-D".into(), "-i".into(), "-f".into(), conf.clone()],
        ));
        cluster.daemons.push(spawn(
            &slurmd,
            vec![
                "-D".into(),
                "-N".into(),
                "pathlight-node".into(),
                "-f".into(),
                conf,
            ],
        ));
        cluster.wait_until("an idle node", || {
            cluster
                .command("sinfo")
                .args(["-h", "-o", "%t"])
                .output()
                .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
        });
        cluster
    }

    /// A Slurm client command talking to this cluster.
    fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command.env("SLURM_CONF", self.dir.path().join("slurm.conf"));
        command
    }

    /// The daemons' logs, for failure messages.
    fn logs(&self) -> String {
        ["munged.log", "slurmctld.log", "slurmd.log"]
            .iter()
            .map(|name| {
                let text = std::fs::read_to_string(self.dir.path().join(name)).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(15).collect();
                format!(
                    "--- {name}:\n{}",
                    tail.into_iter().rev().collect::<Vec<_>>().join("\n")
                )
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    fn wait_until(&self, what: &str, mut ready: impl FnMut() -> bool) {
        let started = Instant::now();
        while !ready() {
            assert!(
                started.elapsed() < TIMEOUT,
                "no {what} after {TIMEOUT:?}\n{}",
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for daemon in self.daemons.iter_mut().rev() {
            let _ = daemon.kill();
            let _ = daemon.wait();
        }
    }
}

#[test]
fn a_slurm_job_array_and_its_merge_equal_one_render() {
    let cluster = Cluster::start();
    let out = tempfile::tempdir().unwrap();
    let options = [
        "--backend",
        "cpu",
        "--width",
        "32",
        "--height",
        "24",
        "--spp",
        "10",
    ];
    let single = out.path().join("single.exr");
    let status = Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .arg("render")
        .args(options)
        .arg("-o")
        .arg(&single)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());

    let jobs = out.path().join("jobs");
    let submitted = cluster
        .command("bash")
        .arg(repo().join("examples/slurm/submit.sh"))
        .arg("4")
        .arg(&jobs)
        .args(options)
        .env("PATHLIGHT", env!("CARGO_BIN_EXE_pathlight"))
        .output()
        .unwrap();
    assert!(
        submitted.status.success(),
        "submit.sh: {}{}",
        String::from_utf8_lossy(&submitted.stderr),
        cluster.logs()
    );
    let merged = jobs.join("image.exr");
    let log = |name: &str| std::fs::read_to_string(jobs.join(name)).unwrap_or_default();
    cluster.wait_until("merged image", || {
        merged.exists() && log("merge.log").contains("merged 4 parts")
    });
    for task in 0..4 {
        assert!(
            log(&format!("part-{task}.log")).contains(&format!("shard {task} of 4")),
            "task {task}: {}",
            log(&format!("part-{task}.log"))
        );
    }
    assert!(
        std::fs::read(&merged).unwrap() == std::fs::read(&single).unwrap(),
        "the merged image differs from the single render\n{}",
        log("merge.log")
    );
}
