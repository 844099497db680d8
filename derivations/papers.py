"""The papers the derivations reproduce, cited once, named the same way everywhere.

Each :class:`Paper` holds what the paper's own text prints (authors, title, venue, year, pages,
DOI); where the text we have does not print a field, ``note`` says so rather than guessing.
Reports, C headers and manifests cite a paper with :meth:`Paper.reference`, and refer to it in
running text with :attr:`Paper.short`; README.md's "Papers" section lists the same references
(a test keeps them equal).
"""

from __future__ import annotations

from dataclasses import dataclass

from uvsym.errors import UnknownNameError

__all__ = ["PAPERS", "Paper", "paper"]


@dataclass(frozen=True)
class Paper:
    """One cited paper: ``short`` is its name in running text (e.g. ``Liu et al. 2014``)."""

    key: str
    short: str
    authors: str
    title: str
    venue: str
    note: str = ""

    def reference(self) -> str:
        """The full reference in one line: authors, title, venue (with year, volume, pages, DOI)."""
        text = f"{self.authors}. {self.title}." + (f" {self.venue}." if self.venue else "")
        return f"{text} {self.note}" if self.note else text


PAPERS: dict[str, Paper] = {p.key: p for p in (
    Paper("liu2014", "Liu et al. 2014",
          "Liu Fuqiang, Xu Demin, Gao Jian, Zhang Lichuan",
          "Fault diagnosis and fault tolerant control for actuators of underwater vehicles "
          "(水下航行器执行机构的故障诊断与容错控制)",
          "Control Theory & Applications (控制理论与应用), 2014",
          "Received 2013-12-11, accepted 2014-05-31; Northwestern Polytechnical University."),
    Paper("zhu-lms", "Zhu et al. (LMS-FIR)",
          "Zhu Daqi et al. (朱大奇等)",
          "A sensor fault diagnosis and fault-tolerant control method for underwater robots "
          "(一种水下机器人传感器故障诊断与容错控制方法)",
          "Issue no. 9",
          "The text we have prints neither the journal's name nor the year."),
    Paper("yang-uio", "Yang, Hu and Zhang (UIO-zonotope)",
          "Yang Yuwei, Hu Zhi, Zhang Wei (楊雨薇, 胡陟, 章偉), Shanghai University of Engineering Science",
          "Quadrotor actuator fault detection with an unknown-input observer and zonotope thresholds",
          "",
          "The text we have prints no title, journal or year; the title above describes its content."),
    Paper("li2025", "Li et al. 2025",
          "Li Changlong, Xiao Changshi, Li Haoxin, Liu Jiaxuan, Li Qiliang, Zhou Chunhui",
          "Fault diagnosis method for unmanned boat propulsion based on FUKF-MMAE "
          "(基于FUKF-MMAE的无人艇推进器故障诊断方法)",
          "Ship Science and Technology (舰船科学技术), 2025, 47(21): 73-80, doi:10.3404/j.issn.1672-7649.2025.21.013"),
    Paper("yu2018", "Yu et al. 2018",
          "Yu Xiaoqing, Jiang Bin, Zhang Ke",
          "Diagnosis of incipient sensor faults and application in motors (传感器微小故障诊断及在电机上的应用)",
          "Journal of Nanjing University of Aeronautics & Astronautics (南京航空航天大学学报), 2018, 50(3): 321-328"),
)}


def paper(key: str) -> Paper:
    """The paper ``key`` (``liu2014``, ``zhu-lms``, ``yang-uio``, ``li2025``, ``yu2018``)."""
    if key not in PAPERS:
        raise UnknownNameError(f"unknown paper {key!r}; known: {', '.join(PAPERS)}")
    return PAPERS[key]
