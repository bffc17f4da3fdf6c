"""Our control_msgs (msg_defs/control_msgs) is wire-identical to ROS 2 Jazzy's (control_msgs 5.x,
its `jazzy` branch): every type's RIHS01 hash, as Jazzy's own generator computes it from our
files, equals the hash of Jazzy's definitions, and so does the hash the installed control_msgs
declares (ours where we built it, a ROS install's otherwise). An independent implementation
(rosbags' hash_rihs01) agrees for every message, the actions' Goal, Result and Feedback included.

JAZZY_HASHES were computed with the same generator from control_msgs' `jazzy` branch (commit
f901df2, 5.8.0) files; they were not compared with a ROS install (none on this machine)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from type_hashes import generator_hashes, installed_hashes, interface_files

OURS = Path(__file__).resolve().parent.parent / "msg_defs" / "control_msgs"
DEPENDENCIES = ["action_msgs", "builtin_interfaces", "geometry_msgs", "sensor_msgs", "service_msgs",
                "std_msgs", "trajectory_msgs", "unique_identifier_msgs"]
ACTION_PARTS = ("Goal", "Result", "Feedback")

JAZZY_HASHES = {
    'control_msgs/action/FollowJointTrajectory': '738ebcb7a2d7cfa42f9f1001cc99ce3a4383d1cfe508015d9be8485e4b1c66f6',
    'control_msgs/action/FollowJointTrajectory_Feedback': '3fd0aaecf71725121ae1ff7f01098a5e0da581e672be18a6b2c286cb43d96b49',
    'control_msgs/action/FollowJointTrajectory_FeedbackMessage': '80398fcb9674a79081a9906e2ccf0c804dd7cb15e22e362e606ee87186beab71',
    'control_msgs/action/FollowJointTrajectory_GetResult': 'e3ceb38e3e1867c8dc0f46014df26e90eb93422f27e9e97f936e07f94be4bc8b',
    'control_msgs/action/FollowJointTrajectory_GetResult_Event': '43161a489e52daaa5bbc2fa74f73f1804d099574fcf8f819170807d75472662a',
    'control_msgs/action/FollowJointTrajectory_GetResult_Request': 'ecf7ea8463d3beec7084bca75216d0b01b87b6e1e4e09679bb26093041efcbe9',
    'control_msgs/action/FollowJointTrajectory_GetResult_Response': '08eefbaa146ce02ba45898d5e99160afd6c4c54a30d159aee0f2ca6035b1580f',
    'control_msgs/action/FollowJointTrajectory_Goal': '8a9060704b269608f5a340934cc26e66869dd14bdac29e2e7fd9ec8b9882d205',
    'control_msgs/action/FollowJointTrajectory_Result': '8002e99ed2c14c6faa522f2a93c26d744c5982f254f9e98ff9c6f19789bdb220',
    'control_msgs/action/FollowJointTrajectory_SendGoal': 'b13789dddc325a7a962825c45e28c77d37237ec129dd0c34dc5994562938c57f',
    'control_msgs/action/FollowJointTrajectory_SendGoal_Event': '906dd566308db02673c73c654f69bdd84738589629c1bc2841ddb49059ed1c6f',
    'control_msgs/action/FollowJointTrajectory_SendGoal_Request': '179c93691f1f6d1d115881ff88c3917b7cc6eac2ba4bf56766cc7c4389e19ef1',
    'control_msgs/action/FollowJointTrajectory_SendGoal_Response': 'e6a48ba740ae254500129a877f0b071be8663a115da1a539b74599cc97921fbf',
    'control_msgs/action/GripperCommand': 'e17c0e644eccf14bea84a0a93e0977182872c2eb7873ca6694900059b46dbc84',
    'control_msgs/action/GripperCommand_Feedback': '8f7c520077bab528bb9161ee3b83c81eee1f8aecadb8922ce82c79d667a819c4',
    'control_msgs/action/GripperCommand_FeedbackMessage': '392ff03fcd872f9dc2405cbeb2897fcf011ad9998458b6aa85c603b8a49e431d',
    'control_msgs/action/GripperCommand_GetResult': '7e60a7606063d4a2728d21badac099e68b734a196ac3ab42d1d4c668eb0bb3cd',
    'control_msgs/action/GripperCommand_GetResult_Event': 'c6a1f7afeb87bf8b3165bd7b03ec0173ffada35f083a583144ab7ac96edc5a04',
    'control_msgs/action/GripperCommand_GetResult_Request': '1a3308da3acbc62cd8a3c823de80ba9e5f9b6bb6f6056d1ad6b29f5f285f97ae',
    'control_msgs/action/GripperCommand_GetResult_Response': '32ed5e1b5906767a3e9914dca4c4aed22529918f6c2360e6fb382363d4df4b45',
    'control_msgs/action/GripperCommand_Goal': '607d9f41eb241e1922e90f02125e87ae6bfb78f7f64a71dc92630263d01f8b6d',
    'control_msgs/action/GripperCommand_Result': 'bf512d5aa6a0e4fe4d8be22b2ec4a1973c3d250fa1f65e47450322c25c45c0a0',
    'control_msgs/action/GripperCommand_SendGoal': '6bf8cc4ce80cd499e7dd3258c03c50c3fa6672b469ff8355339ef1df77fcd212',
    'control_msgs/action/GripperCommand_SendGoal_Event': '5c80eac98bcde7d64faf4b94f77ef69f12e442870dc1eba26d25b4681ef9ac0a',
    'control_msgs/action/GripperCommand_SendGoal_Request': '1b869b7b4042272dc0f8ed65468c4e57c9e532ea5e53ce74fda0767eefbfa983',
    'control_msgs/action/GripperCommand_SendGoal_Response': '0c8dda5e9d39ab5e3162b66e79b292a4258659ddfcf8722d39463f718b6c59bc',
    'control_msgs/action/ParallelGripperCommand': 'adfd3c1ebe8abc38ebcc0e454b6423d291d4010dd5697d14eca5b9be4726ae18',
    'control_msgs/action/ParallelGripperCommand_Feedback': 'ed6f7c4e5aea7f960432663c0e762e001a0a1f5cc0130d126e60041412d0543c',
    'control_msgs/action/ParallelGripperCommand_FeedbackMessage': 'c61f4cf99d06c5a3e24bed17c2910bdf66a30d89461e2ac7b5fd538a34b022cc',
    'control_msgs/action/ParallelGripperCommand_GetResult': 'e4c7f0e8a831ce5625ed20abcd13796406d945f92ebc7ad5972e0b0d29b381bd',
    'control_msgs/action/ParallelGripperCommand_GetResult_Event': 'bb81e07fe7a231c5de7b957f0384ea31600b8a808cf83e820e213b7216ebf12e',
    'control_msgs/action/ParallelGripperCommand_GetResult_Request': 'cea82415cadc3288fdfa8aaba509e9939732aaecac6edf9cb954e5a7161646ec',
    'control_msgs/action/ParallelGripperCommand_GetResult_Response': 'c973b1bb9b454de1c3f38a2af9d45bc1930b809f746d6d6ec91bb3c783cb09eb',
    'control_msgs/action/ParallelGripperCommand_Goal': '412807b6b6acf2bf406fb0cf3b5c8f84286cd4e4d425734155aa1ff41caa0063',
    'control_msgs/action/ParallelGripperCommand_Result': '51acbcd62aa44097d3877c506eab1146856fa8768628ffbe102c1699152d2afa',
    'control_msgs/action/ParallelGripperCommand_SendGoal': '567c37373fed1260adbe047415688c73e4f3e94b2e3982761ecc71fd63d710a7',
    'control_msgs/action/ParallelGripperCommand_SendGoal_Event': 'b6164adce06de27a3ebd924f198539baf7f929315c825b266c8827de4ca79384',
    'control_msgs/action/ParallelGripperCommand_SendGoal_Request': 'dc8e5d95c0e15af6f03ff237eb8cfdaac14cc2b09f51b363311e98ec0a8487a0',
    'control_msgs/action/ParallelGripperCommand_SendGoal_Response': '613e4f060bff03b152eeaba1f8c6baa9d0309527b28b08bc9aae28ece7ef8b47',
    'control_msgs/msg/GripperCommand': '57eb8f326c9889ca8bb34ead82cc94cc09bf6bc5c3b6c09546dca3a00b589890',
    'control_msgs/msg/JointComponentTolerance': '739ea7566931944d33830fa10f1bf5e7a7fbdc3172bce7a7eaac642bd6e3ffa4',
    'control_msgs/msg/JointJog': 'ba249455a20f70168a1acb7bf43b776b72ff1f7eb5fc4cfea443f749e963c6e7',
    'control_msgs/msg/JointTolerance': 'c254f9cece0f3b733017b6990fd46d1326e25242d6b8844398c97d9a88e7d648',
}
FILES = interface_files(OURS)


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    return generator_hashes("control_msgs", OURS, FILES,
                            tmp_path_factory.mktemp("control_msgs"), DEPENDENCIES)


def test_every_type_hashes_as_jazzys(generated):
    assert {k: v.removeprefix("RIHS01_") for k, v in generated.items()} == JAZZY_HASHES


def test_the_installed_control_msgs_declares_the_same_hashes(generated):
    installed = installed_hashes("control_msgs", FILES)
    assert {k: installed[k] for k in generated} == generated


def _qualified(part: str) -> str:
    """An action part's definition with its package-local types named in full (rosbags would
    look for them beside the action, where rosidl looks in msg/)."""
    return re.sub(r"^([A-Z]\w*)(\[\]|\s)", r"control_msgs/msg/\1\2", part, flags=re.M)


def test_rosbags_hashes_every_message_the_same():
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for path in sorted(OURS.glob("msg/*.msg")):
        types.update(get_types_from_msg(path.read_text(), f"control_msgs/msg/{path.stem}"))
    for path in sorted(OURS.glob("action/*.action")):
        for part, suffix in zip(path.read_text().split("\n---\n"), ACTION_PARTS):
            types.update(get_types_from_msg(_qualified(part),
                                            f"control_msgs/action/{path.stem}_{suffix}"))
    store.register(types)
    assert len(types) == 4 + 3 * len(ACTION_PARTS)
    assert {name: store.hash_rihs01(name).removeprefix("RIHS01_") for name in types} == \
        {name: JAZZY_HASHES[name] for name in types}
